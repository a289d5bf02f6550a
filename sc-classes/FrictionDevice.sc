// One device slot of a server: a simulated friction device, a replay of a recorded session,
// or (later) hardware. Every command has a ...Msg twin that returns the OSC message, so the
// same device can be used in a Score (pass server nil to only describe it).
FrictionDevice {
	classvar <oldSpecNames;
	// Life cycle: the devices sclang holds open, by server and slot; the commands awaiting an
	// answer (/done or /kfFail), by server; how long to wait for one.
	classvar slots, pendingAnswers, responders, <>answerTimeout = 5;
	var <server, <index, <specs, <kind, <source, <overrides;
	var <state = \described, <replace = false, forceBus, forceWriter, positionBus, positionReader;

	*initClass {
		// The names specs had before every name carried its unit. A user may have typed them, so
		// a profile still accepts them and specs still answers to them (through its parent).
		oldSpecNames = (
			updateRate: \updateRateHz, maxSpeed: \maxSpeedMmPerS, minForce: \minForceN,
			maxForce: \maxForceN, audioLatency: \audioLatencyS, tactileLatency: \tactileLatencyS,
			forceFramePeriod: \forceFramePeriodS, maxForceSlew: \maxForceSlewNPerS,
			watchdog: \watchdogS, magnetLag: \magnetLagS
		);
		slots = IdentityDictionary.new;
		pendingAnswers = IdentityDictionary.new;
		responders = IdentityDictionary.new;
		// The server closes every device when it quits; a reboot opens them again, and the
		// force writers come back after Cmd-. (ServerTree runs after boot and after Cmd-.).
		ServerQuit.add({ |srv| this.prServerQuit(srv) }, \all);
		ServerBoot.add({ |srv| this.prServerBoot(srv) }, \all);
		ServerTree.add({ |srv| this.prServerTree(srv) }, \all);
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
	// replace: true closes a device open in the slot; false (the default) refuses the slot.
	*sim { |server, index = 0, hand, profile, replace = false|
		if(hand.notNil and: { hand.isKindOf(FrictionHand).not }) {
			Error("FrictionDevice.sim: hand must be a FrictionHand or nil, got %".format(hand)).throw
		};
		^this.new.prInit(server, index, \sim, hand, profile, replace).prOpen
	}

	// path: a kf-session recording (FrictionDevice.record) or a hid-recorder .hid file.
	*replay { |server, path, index = 0, profile, replace = false|
		if(path.isString.not) { Error("FrictionDevice.replay: path must be a String, got %".format(path)).throw };
		path = path.standardizePath;
		if(server.notNil and: { File.exists(path).not }) {
			Error("FrictionDevice.replay: no such file: %".format(path)).throw
		};
		^this.new.prInit(server, index, \replay, path, profile, replace).prOpen
	}

	// The devices open (or opening) in sclang, on all servers.
	*all { ^slots.values.asArray.collect { |a| a.select(_.notNil) }.flatten(1) }
	// The device sclang holds in a slot of server, or nil.
	*at { |server, index| ^slots[server] !? { |a| a[index] } }

	isOpen { ^state == \open }

	// Audio is delayed by this much so that sound and touch arrive together (the paper: 1 ms).
	audioDelay { ^specs[\tactileLatencyS] - specs[\audioLatencyS] }

	// The plugin command that opens this kind of device.
	openCommand { ^(sim: \kfOpenSim, replay: \kfOpenReplay, mouse: \kfOpenMouse)[kind] }

	openMsg {
		if(kind == \mouse) { ^this.mouseMsg };  // FrictionDeviceMouse.sc
		^if(kind == \sim) {
			['/cmd', \kfOpenSim, index] ++ (source !? { source.asCommandArgs } ?? { [-1, 0] }) ++ this.prOverrideArgs
		} {
			['/cmd', \kfOpenReplay, index, source] ++ this.prOverrideArgs
		} ++ (if(replace) { [\replace, 1] } { [] })
	}

	// The puck's latest reported position becomes (x, y) mm for every reader of the device, from
	// the block the server executes the command in (a bundle's time, in a Score its time).
	zero { |x = 0, y = 0| this.prSendAnswered(\kfZero, this.zeroMsg(x, y)) }
	zeroMsg { |x = 0, y = 0|
		[x, y].do { |v| if(v.isNumber.not or: { v.isNaN } or: { v.abs == inf }) {
			Error("FrictionDevice.zero: x and y must be finite numbers (mm), got %".format(v)).throw } };
		^['/cmd', \kfZero, index, x.asFloat, y.asFloat]
	}
	setPosition { |x = 0, y = 0| this.zero(x, y) }
	setPositionMsg { |x = 0, y = 0| ^this.zeroMsg(x, y) }

	// A one-channel audio Bus of the device's force (N): play sources into it (Ndef(...).play(
	// dev.forceBus.index), Out.ar) and one writer synth, at the tail of the server, sends its sum
	// to the device. A NodeProxy crossfade into it hands the force over smoothly: the proxy
	// fades its old and new sources on its own bus, so the sum stays between the two. Nothing
	// playing into it reads as the device's minimum force.
	forceBus {
		if(server.isNil) { Error("FrictionDevice.forceBus: the device has no server").throw };
		forceBus ?? {
			forceBus = Bus.audio(server, 1);
			this.prStartWriter;
		};
		^forceBus
	}

	// Records reports and force frames to path (kf-session text format); nil stops recording.
	record { |path| this.prSendAnswered(\kfRecord, this.recordMsg(path)) }
	recordMsg { |path| ^['/cmd', \kfRecord, index, path !? { path.standardizePath } ? ""] }
	stopRecording { this.record(nil) }
	stopRecordingMsg { ^this.recordMsg(nil) }

	// Posts the device thread's telemetry in the server's output.
	status { this.prSendAnswered(\kfStatus, this.statusMsg) }
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

	// A 4-channel control Bus of the puck's [x, y, speedX, speedY] (mm, mm/s), made on first
	// use and written by one reader synth at the head of the server: for GUIs and re-centring
	// (positionBus.getn(4, action)); it comes back after Cmd-. and a reboot.
	positionBus {
		if(server.isNil) { Error("FrictionDevice.positionBus: the device has no server").throw };
		positionBus ?? {
			positionBus = Bus.control(server, 4);
			this.prStartReader;
		};
		^positionBus
	}

	prStartReader {
		var def = SynthDef(\kfPositionReader, { Out.kr(\bus.ir(0), FrictionMouseIn.kr(\device.ir(0))) });
		var reader;
		if(positionReader.notNil or: { positionBus.isNil }) { ^this };
		reader = positionReader = Synth.basicNew(\kfPositionReader, server);
		forkIfNeeded {
			def.add;
			server.sync;
			if(positionReader === reader) {
				server.sendMsg(*reader.newMsg(RootNode(server), [\device, index, \bus, positionBus.index], \addToHead));
			};
		};
	}

	// Closes the device if this object still holds its slot (a device opened with replace: true
	// in the same slot is not closed by the object it replaced).
	close {
		if(server.isNil) { ^this };
		if(this.class.at(server, index) !== this) {
			"FrictionDevice: % does not hold slot % (closed or replaced); nothing to close".format(this, index).warn;
			^this
		};
		this.prForget(\closed);
		if(server.serverRunning) { this.prSendAnswered(\kfClose, this.closeMsg) };
	}
	closeMsg { ^['/cmd', \kfClose, index] }

	printOn { |stream| stream << this.class.name << "(" << kind << ", " << index << ")" }

	prInit { |argServer, argIndex, argKind, argSource, profile, argReplace = false|
		if(argReplace != true and: { argReplace != false }) {
			Error("FrictionDevice: replace must be true or false, got %".format(argReplace)).throw
		};
		replace = argReplace;
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
			if(value == true or: { value == false }) { value = value.binaryValue };  // loop: true
			if(value.isNumber.not) { Error("FrictionDevice: setting % must be a number, got %".format(key, value)).throw };
			overrides[oldSpecNames[key] ? key] = value;
		};
		specs = KineticFriction.paperDevice;
		specs.keys.do { |name| overrides[name] !? { |v| specs[name] = v } };
		specs = this.class.specsOf(specs);
	}

	// Opens on the server. Inside a Routine (fork, s.waitForBoot, Tdef) it waits for the answer
	// and a refusal is an Error; elsewhere the refusal is posted as an ERROR when it comes.
	prOpen {
		if(server.isNil) { ^this };
		if(server.serverRunning.not) { Error("FrictionDevice: server % is not running".format(server)).throw };
		state = \opening;
		// The server decides whether the slot is free (or replaced): it holds the devices of
		// every client. Its answer updates what sclang holds.
		this.prSendAnswered(this.openCommand, this.openMsg, {
			this.prHold;
		}, {
			state = \failed;
		});
	}

	prHold {
		var previous = this.class.at(server, index);
		if(previous.notNil and: { previous !== this }) { previous.prForget(\replaced) };
		slots[server] = slots[server] ?? { Array.newClear(16) };
		slots[server][index] = this;
		state = \open;
		forceBus !? { this.prStartWriter };
		positionBus !? { this.prStartReader };
	}

	// Sends msg and awaits /done cmd or /kfFail for this slot (answerTimeout s at most).
	// Sends a command nothing waits for (the board's: the server posts their result).
	prSend { |msg|
		if(server.isNil) { ^this };
		if(server.serverRunning.not) { Error("FrictionDevice: server % is not running".format(server)).throw };
		server.listSendMsg(msg)
	}

	prSendAnswered { |cmd, msg, onDone, onFail, block = true|
		var cond, answer, inRoutine = block and: { thisThread.isKindOf(Routine) };
		if(server.isNil) { ^this };
		// (At ServerBoot, re-opening, the server is up but not yet marked running.)
		if(block and: { server.serverRunning.not }) {
			Error("FrictionDevice: server % is not running".format(server)).throw
		};
		cond = Condition(false);
		this.class.prExpect(server, cmd, index, {
			answer = \done;
			onDone.value;
			cond.test = true; cond.signal;
		}, { |reason|
			answer = reason;
			onFail.value(reason);
			if(inRoutine.not) { ("ERROR: " ++ this.prFailText(cmd, reason)).postln };
			cond.test = true; cond.signal;
		});
		server.listSendMsg(msg);
		if(inRoutine) {
			cond.wait;
			if(answer != \done) { Error(this.prFailText(cmd, answer)).throw };
		};
	}

	// The server's reasons name their command already ("kfOpenSim: ..."); ours do not.
	prFailText { |cmd, reason|
		^if(reason.beginsWith(cmd.asString ++ ":")) {
			"FrictionDevice " ++ reason
		} {
			"FrictionDevice %: %".format(cmd, reason)
		}
	}

	prForget { |newState|
		var held = slots[server];
		if(held.notNil and: { held[index] === this }) { held[index] = nil };
		state = newState;
		forceWriter !? { if(server.serverRunning) { forceWriter.free } };
		forceWriter = nil;
		forceBus !? { forceBus.free };
		forceBus = nil;
		positionReader !? { if(server.serverRunning) { positionReader.free } };
		positionReader = nil;
		positionBus !? { positionBus.free };
		positionBus = nil;
	}

	// One writer per device, claimed at once so that it is never started twice.
	prStartWriter {
		var def = SynthDef(\kfForceWriter, { FrictionOut.ar(\device.ir(0), In.ar(\bus.ir(0), 1)) });
		var writer;
		if(forceWriter.notNil or: { forceBus.isNil }) { ^this };
		writer = forceWriter = Synth.basicNew(\kfForceWriter, server);
		forkIfNeeded {
			def.add;
			server.sync;
			if(forceWriter === writer) {
				server.sendMsg(*writer.newMsg(RootNode(server), [\device, index, \bus, forceBus.index], \addToTail));
			};
		};
	}

	*prExpect { |server, cmd, index, done, fail|
		var list = pendingAnswers[server] ?? { List.new };
		var entry = (cmd: cmd, index: index, done: done, fail: fail);
		pendingAnswers[server] = list;
		list.add(entry);
		responders[server] ?? {
			responders[server] = [
				OSCFunc({ |msg|
					var found = list.detect { |e| e[\cmd] == msg[1] };
					found !? { list.remove(found); found[\done].value };
				}, '/done', server.addr).permanent_(true),
				OSCFunc({ |msg|
					var found = list.detect { |e| e[\index] == msg[2] };
					var reason = msg[3..].collect { |c| c.asInteger.asAscii }.join;
					found !? { list.remove(found); found[\fail].value(reason) };
				}, '/kfFail', server.addr).permanent_(true)
			]
		};
		SystemClock.sched(answerTimeout, {
			if(list.includes(entry)) {
				list.remove(entry);
				fail.value("no answer from % in % s".format(server, answerTimeout));
			};
			nil
		});
	}

	*prServerQuit { |srv|
		// The server closed them; they are opened again at the next boot.
		slots[srv] !? { |held| held.do { |dev| dev !? { dev.prQuit } } };
		pendingAnswers[srv] !? { |list| list.copy.do { |e| list.remove(e); e[\fail].value("the server quit") } };
	}

	*prServerBoot { |srv|
		slots[srv] !? { |held| held.do { |dev| dev !? { dev.prReopen } } };
	}

	*prServerTree { |srv|
		slots[srv] !? { |held| held.do { |dev| dev !? { dev.prRestoreWriter } } };
	}

	prQuit { state = \quit; forceWriter = nil; positionReader = nil }

	prReopen {
		if(state != \quit) { ^this };
		forceBus !? { server.audioBusAllocator.reserve(forceBus.index, 1, false) };
		positionBus !? { server.controlBusAllocator.reserve(positionBus.index, 4, false) };
		state = \opening;
		this.prSendAnswered(this.openCommand, this.openMsg, {
			state = \open;
			this.prStartWriter;
			this.prStartReader;
		}, {
			this.prForget(\failed);
		}, false);
	}

	// After Cmd-. (all nodes freed): the force writer again.
	prRestoreWriter {
		if(state == \open) {
			forceWriter = nil;
			positionReader = nil;
			this.prStartWriter;
			this.prStartReader;
		};
	}

	// In a ProxySpace (~dev = FrictionDevice.sim(s)), the proxy plays the puck's position and
	// speed [x, y, speedX, speedY] at control rate; ~dev.source is the device.
	prepareForProxySynthDef { ^{ FrictionMouseIn.kr(index) } }

	prOverrideArgs {
		^overrides.asSortedArray.flatten(1).collect { |v| if(v.isKindOf(Symbol)) { v.asString } { v } }
	}
}
