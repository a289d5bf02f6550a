// One device slot of a server: a simulated friction device, a replay of a recorded session,
// or (later) hardware. Every command has a ...Msg twin that returns the OSC message, so the
// same device can be used in a Score (pass server nil to only describe it).
FrictionDevice {
	classvar <paperSpecs, <settingNames;
	var <server, <index, <specs, <kind, <source, <overrides;

	*initClass {
		// DESIGN.md's names for the device's numbers, and the device library's setting names
		// (with their units) that profiles use; either may be given in a profile.
		settingNames = (
			countMm: \countMm, updateRate: \updateRateHz, maxCountsPerReport: \maxCountsPerReport,
			minForce: \minForceN, maxForce: \maxForceN, audioLatency: \audioLatencyS,
			tactileLatency: \tactileLatencyS, forceFramePeriod: \forceFramePeriodS,
			maxForceSlew: \maxForceSlewNPerS, watchdog: \watchdogS, magnetLag: \magnetLagS
		);
		paperSpecs = (
			countMm: 0.021, updateRate: 125, maxCountsPerReport: 127, minForce: 0.14, maxForce: 1.4,
			audioLatency: 0.0014, tactileLatency: 0.0024, forceFramePeriod: 0.001, maxForceSlew: 2000,
			watchdog: 0.05, magnetLag: 0.0024
		);
		paperSpecs[\maxSpeed] = this.maxSpeedOf(paperSpecs);
	}

	// counts x count size x update rate: 333.375 mm/s for the paper's device (the paper says 334).
	*maxSpeedOf { |specs| ^specs[\countMm] * specs[\maxCountsPerReport] * specs[\updateRate] }

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
	audioDelay { ^specs[\tactileLatency] - specs[\audioLatency] }

	openMsg {
		if(kind == \mouse) { ^this.mouseMsg };  // FrictionDeviceMouse.sc
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
			overrides[settingNames[key] ? key] = value;  // DESIGN names become setting names
		};
		specs = paperSpecs.copy;
		settingNames.keysValuesDo { |name, setting| overrides[setting] !? { |v| specs[name] = v } };
		specs[\maxSpeed] = this.class.maxSpeedOf(specs);
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
