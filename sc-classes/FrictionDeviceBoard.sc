// FrictionDevice with the friction board (device/board/PROTOCOL.md), the USB electromagnet
// driver: added to a device so that its force frames also drive the magnet, armed, calibrated,
// asked for its telemetry. Its commands are answered as every device command is
// (FrictionAnswers): inside a Routine they wait, and a refusal is an Error with the server's reason.
+ FrictionDevice {

	// The friction board, added to this device: every force frame goes to it too, through the
	// calibration. serial: nil for the first board found; emulate: true for the board emulator
	// (no hardware needed). The board starts disarmed.
	addBoard { |serial, emulate = false, inFlight = 2|
		this.prSendAnswered(\kfBoardOpen, this.addBoardMsg(serial, emulate, inFlight))
	}
	addBoardMsg { |serial, emulate = false, inFlight = 2|
		if(serial.notNil and: { serial.isString.not and: { serial.isKindOf(Symbol).not } }) {
			Error("FrictionDevice.addBoard: serial must be a String or nil, got %".format(serial)).throw
		};
		if(inFlight.isInteger.not or: { inFlight < 1 or: { inFlight > 4 } }) {
			Error("FrictionDevice.addBoard: inFlight must be an Integer from 1 to 4, got %".format(inFlight)).throw
		};
		^['/cmd', \kfBoardOpen, index, (serial ? "").asString, emulate.binaryValue, inFlight]
	}

	// The magnet is driven only while the board is armed.
	arm { this.prSendAnswered(\kfBoardArm, this.armMsg) }
	armMsg { ^['/cmd', \kfBoardArm, index, 1] }
	disarm { this.prSendAnswered(\kfBoardArm, this.disarmMsg) }
	disarmMsg { ^['/cmd', \kfBoardArm, index, 0] }

	// calibration: a FrictionCalibration (written to a file first) or a path; nil: linear.
	calibrate { |calibration| this.prSendAnswered(\kfBoardCalibrate, this.calibrateMsg(calibration)) }
	calibrateMsg { |calibration|
		var path = calibration;
		if(calibration.isKindOf(FrictionCalibration)) {
			path = calibration.path ?? {
				Error("FrictionDevice.calibrate: write the FrictionCalibration to a file first").throw
			}
		};
		if(path.notNil and: { path.isString.not }) {
			Error("FrictionDevice.calibrate: give a FrictionCalibration, a path or nil, got %".format(
				calibration)).throw
		};
		^['/cmd', \kfBoardCalibrate, index, path !? { path.standardizePath } ? ""]
	}

	// The board's and the frame timing's telemetry as an Event, passed to action (the reply
	// goes to clients registered with /notify, as sclang is by default).
	boardStatus { |action|
		if(server.isNil) { ^this };
		OSCFunc({ |msg| action.value(this.class.boardStatusOf(msg[3..])) }, '/kfBoardStatus', server.addr,
			argTemplate: [nil, index]).oneShot;
		this.prSendAnswered(\kfBoardStatus, this.boardStatusMsg)
	}
	boardStatusMsg { ^['/cmd', \kfBoardStatus, index] }
	*boardStatusOf { |values|
		var names = #[hasBoard, connected, armed, boardState, currentLevel, temperatureC, errors, setPointsSent,
			late, lost, timeouts, partials, stalls, badStatus, unplugs, reopens, onePerPump, offsetP50S];
		var event = ();
		names.do { |name, i| event[name] = values[i] };
		#[hasBoard, connected, armed].do { |name| event[name] = event[name] == 1 };
		event[\boardState] = [\disarmed, \armed, \fault][event[\boardState]] ? \unknown;
		^event
	}

	removeBoard { this.prSendAnswered(\kfBoardClose, this.removeBoardMsg) }
	removeBoardMsg { ^['/cmd', \kfBoardClose, index] }
}
