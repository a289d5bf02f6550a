// FrictionDevice with the friction board (device/board/PROTOCOL.md), the USB electromagnet
// driver: added to a device so that its force frames also drive the magnet, armed, calibrated,
// asked for its telemetry. Its commands are answered as every device command is
// (FrictionAnswers): inside a Routine they wait, and a refusal is an Error with the server's
// reason; elsewhere a refusal is posted as an ERROR when it comes. The device remembers its
// board and calibration, and opens them again with it after a reboot.
+ FrictionDevice {

	// The friction board, added to this device: every force frame goes to it too, through the
	// calibration. serial: nil for the first board found; emulate: true for the board emulator
	// (no hardware needed). The board starts disarmed. A replay device cannot carry a board (its
	// puck is a recording), nor can a device of a Score or NRT server (the server refuses it: the
	// board runs in real time only).
	addBoard { |serial, emulate = false, inFlight = 2|
		this.prSendAnswered(\kfBoardOpen, this.addBoardMsg(serial, emulate, inFlight), {
			boardSetup = (serial: serial, emulate: emulate, inFlight: inFlight);
		})
	}
	addBoardMsg { |serial, emulate = false, inFlight = 2|
		if(kind == \replay) {
			Error(("FrictionDevice.addBoard: % replays a recording, whose puck is not the one on the magnet: "
				++ "add the board to a mouse (or simulated) device").format(this)).throw
		};
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
	calibrate { |calibration|
		this.prSendAnswered(\kfBoardCalibrate, this.calibrateMsg(calibration), {
			boardSetup !? { boardSetup[\calibration] = calibration };
		})
	}
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

	// FrictionDevice.hardware's board: nil (the first board), a serial, or \emulate; checked here,
	// before anything is sent, with the calibration.
	prInitBoard { |board, calibration, where|
		var serial = board, emulate = false;
		if(board == \emulate) { serial = nil; emulate = true };
		if(serial.notNil and: { serial.isString.not and: { serial.isKindOf(Symbol).not } }) {
			Error("%: board must be nil (the first board), a serial String or \\emulate, got %".format(
				where, board)).throw
		};
		boardSetup = (serial: serial, emulate: emulate, inFlight: 2, calibration: calibration);
		this.prOpenSteps;  // their arguments' errors now
	}

	// The board's and the frame timing's telemetry as an Event (boardStatusOf; hasBoard false for
	// a device without a board), passed to action, or posted when there is none. Inside a Routine
	// it waits and also returns the Event; an empty slot is refused (an Error there, an ERROR
	// posted elsewhere). The reply goes to clients registered with /notify, as sclang is by
	// default, and comes before the command's own answer.
	boardStatus { |action|
		var values, reply;
		if(server.isNil) { ^this };
		reply = OSCFunc({ |msg| values = this.class.boardStatusOf(msg[3..]) }, '/kfBoardStatus', server.addr,
			argTemplate: [nil, index]).oneShot;
		this.prSendAnswered(\kfBoardStatus, this.boardStatusMsg, {
			reply.free;
			if(action.notNil) { action.value(values) } { "% board status: %".format(this, values).postln };
		}, { reply.free });
		^values
	}
	boardStatusMsg { ^['/cmd', \kfBoardStatus, index] }
	*boardStatusOf { |values|
		var names = #[hasBoard, connected, armed, boardState, currentLevel, temperatureC, errors, setPointsSent,
			late, lost, timeouts, partials, stalls, badStatus, unplugs, reopens, onePerPump, offsetP50S,
			forceRateHz, levelsPadded, levelsDropped];
		var event = ();
		names.do { |name, i| event[name] = values[i] };
		#[hasBoard, connected, armed].do { |name| event[name] = event[name] == 1 };
		event[\boardState] = [\disarmed, \armed, \fault][event[\boardState]] ? \unknown;
		^event
	}

	removeBoard { this.prSendAnswered(\kfBoardClose, this.removeBoardMsg, { boardSetup = nil }) }
	removeBoardMsg { ^['/cmd', \kfBoardClose, index] }
}
