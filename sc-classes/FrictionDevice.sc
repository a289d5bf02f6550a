// One device slot of a server: a simulated friction device, a replay of a recorded session,
// or (later) hardware. Every command has a ...Msg twin that returns the OSC message, so the
// same device can be used in a Score (pass server nil to only describe it).
FrictionDevice {
	classvar <oldSpecNames;
	var <server, <index, <specs, <kind, <source, <overrides;

	*initClass {
		// The names specs had before every name carried its unit. A user may have typed them, so
		// a profile still accepts them and specs still answers to them (through its parent).
		oldSpecNames = (
			updateRate: \updateRateHz, maxSpeed: \maxSpeedMmPerS, minForce: \minForceN,
			maxForce: \maxForceN, audioLatency: \audioLatencyS, tactileLatency: \tactileLatencyS,
			forceFramePeriod: \forceFramePeriodS, maxForceSlew: \maxForceSlewNPerS,
			watchdog: \watchdogS, magnetLag: \magnetLagS
		);
	}

	// The paper's device numbers (profiles/paper.json) and its top speed, as specs has them.
	*paperSpecs { ^this.specsOf(KineticFriction.paperDevice) }

	// settings (device setting names) with maxSpeedMmPerS added and the old names as aliases.
	*specsOf { |settings|
		var specs = settings.copy;
		specs[\maxSpeedMmPerS] = this.maxSpeedOf(specs);
		specs.parent = oldSpecNames.collect { |name| specs[name] };
		^specs
	}

	// counts x count size x update rate: 333.375 mm/s for the paper's device (the paper says 334).
	*maxSpeedOf { |specs| ^specs[\countMm] * specs[\maxCountsPerReport] * specs[\updateRateHz] }

	// hand: a FrictionHand (nil: the puck stays put). profile: an Event of spec or simulation
	// settings by name (e.g. (maxForceN: 1.0, puckMassKg: 0.2)); nil: the paper's numbers.
	*sim { |server, index = 0, hand, profile|
		if(hand.notNil and: { hand.isKindOf(FrictionHand).not }) {
			Error("FrictionDevice.sim: hand must be a FrictionHand or nil, got %".format(hand)).throw
		};
		^this.new.prInit(server, index, \sim, hand, profile).prOpen
	}

	// path: a kf-session recording (FrictionDevice.record) or a hid-recorder .hid file.
	*replay { |server, path, index = 0, profile|
		if(path.isString.not) { Error("FrictionDevice.replay: path must be a String, got %".format(path)).throw };
		path = path.standardizePath;
		if(server.notNil and: { File.exists(path).not }) {
			Error("FrictionDevice.replay: no such file: %".format(path)).throw
		};
		^this.new.prInit(server, index, \replay, path, profile).prOpen
	}

	// Audio is delayed by this much so that sound and touch arrive together (the paper: 1 ms).
	audioDelay { ^specs[\tactileLatencyS] - specs[\audioLatencyS] }

	openMsg {
		^if(kind == \sim) {
			['/cmd', \kfOpenSim, index] ++ (source !? { source.asCommandArgs } ?? { [-1, 0] }) ++ this.prOverrideArgs
		} {
			['/cmd', \kfOpenReplay, index, source] ++ this.prOverrideArgs
		}
	}

	// Records reports and force frames to path (kf-session text format); nil stops recording.
	record { |path| this.prSend(this.recordMsg(path)) }
	recordMsg { |path| ^['/cmd', \kfRecord, index, path !? { path.standardizePath } ? ""] }
	stopRecording { this.record(nil) }
	stopRecordingMsg { ^this.recordMsg(nil) }

	// Posts the device thread's telemetry in the server's output.
	status { this.prSend(this.statusMsg) }
	statusMsg { ^['/cmd', \kfStatus, index] }

	// The friction board (device/PROTOCOL.md), added to this device: every force frame goes to
	// it too, through the calibration. serial: nil for the first board found; emulate: true for
	// the board emulator (no hardware needed). The board starts disarmed.
	addBoard { |serial, emulate = false, inFlight = 2| this.prSend(this.addBoardMsg(serial, emulate, inFlight)) }
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
	arm { this.prSend(this.armMsg) }
	armMsg { ^['/cmd', \kfBoardArm, index, 1] }
	disarm { this.prSend(this.disarmMsg) }
	disarmMsg { ^['/cmd', \kfBoardArm, index, 0] }
	// calibration: a FrictionCalibration (written to a file first) or a path; nil: linear.
	calibrate { |calibration| this.prSend(this.calibrateMsg(calibration)) }
	calibrateMsg { |calibration|
		var path = calibration;
		if(calibration.isKindOf(FrictionCalibration)) {
			path = calibration.path ?? {
				Error("FrictionDevice.calibrate: write the FrictionCalibration to a file first").throw
			}
		};
		if(path.notNil and: { path.isString.not }) {
			Error("FrictionDevice.calibrate: give a FrictionCalibration, a path or nil, got %".format(calibration)).throw
		};
		^['/cmd', \kfBoardCalibrate, index, path !? { path.standardizePath } ? ""]
	}
	// The board's and the frame timing's telemetry as an Event, passed to action (the reply
	// goes to clients registered with /notify, as sclang is by default).
	boardStatus { |action|
		if(server.isNil) { ^this };
		OSCFunc({ |msg| action.value(this.class.boardStatusOf(msg[3..])) }, '/kfBoardStatus', server.addr,
			argTemplate: [nil, index]).oneShot;
		this.prSend(this.boardStatusMsg)
	}
	boardStatusMsg { ^['/cmd', \kfBoardStatus, index] }
	*boardStatusOf { |values|
		var names = #[hasBoard, connected, armed, boardState, currentLevel, temperatureC, errors, setPointsSent, late,
			lost, timeouts, partials, stalls, badStatus, unplugs, reopens, onePerPump, offsetP50S];
		var event = ();
		names.do { |name, i| event[name] = values[i] };
		#[hasBoard, connected, armed].do { |name| event[name] = event[name] == 1 };
		event[\boardState] = [\disarmed, \armed, \fault][event[\boardState]] ? \unknown;
		^event
	}
	removeBoard { this.prSend(this.removeBoardMsg) }
	removeBoardMsg { ^['/cmd', \kfBoardClose, index] }

	close { this.prSend(this.closeMsg) }
	closeMsg { ^['/cmd', \kfClose, index] }

	printOn { |stream| stream << this.class.name << "(" << kind << ", " << index << ")" }

	prInit { |argServer, argIndex, argKind, argSource, profile|
		if(argIndex.isInteger.not or: { argIndex < 0 or: { argIndex > 15 } }) {
			Error("FrictionDevice: index must be an Integer from 0 to 15, got %".format(argIndex)).throw
		};
		if(profile.notNil and: { profile.isKindOf(Dictionary).not }) {
			Error("FrictionDevice: profile must be an Event of settings, got %".format(profile)).throw
		};
		server = argServer;
		index = argIndex;
		kind = argKind;
		source = argSource;
		overrides = ();
		(profile ? ()).keysValuesDo { |key, value|
			if(value.isNumber.not) { Error("FrictionDevice: setting % must be a number, got %".format(key, value)).throw };
			overrides[oldSpecNames[key] ? key] = value;
		};
		specs = KineticFriction.paperDevice;
		specs.keys.do { |name| overrides[name] !? { |v| specs[name] = v } };
		specs = this.class.specsOf(specs);
	}

	prOpen { this.prSend(this.openMsg) }

	prSend { |msg|
		if(server.isNil) { ^this };
		if(server.serverRunning.not) {
			Error("FrictionDevice: server % is not running".format(server)).throw
		};
		server.listSendMsg(msg)
	}

	prOverrideArgs {
		^overrides.asSortedArray.flatten(1).collect { |v| if(v.isKindOf(Symbol)) { v.asString } { v } }
	}
}
