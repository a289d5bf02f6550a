// One device slot of a server: a simulated friction device, a replay of a recorded session, or
// hardware: a real mouse (hidapi or evdev, extFrictionDeviceMouse.sc) as the puck's sensor, and the
// friction board (libusb, extFrictionDeviceBoard.sc) driving its magnet. Every command has a ...Msg
// twin that returns the OSC message, so the same device can be used in a Score: describeSim,
// describeReplay and describeMouse make a device without opening it. A nil server is
// Server.default, as everywhere in SC. The server's answers to the commands are FrictionAnswers'.
FrictionDevice {
	classvar <oldSpecNames;
	// The devices sclang holds open, by server and slot.
	classvar slots;
	var <server, <index, <specs, <kind, <source, <overrides;
	// busSynths: the writer of forceBus and the reader of positionBus, by role (\writer, \reader).
	var <state = \described, <replace = false, forceBus, positionBus, busSynths;
	// The board the device carries, opened with it (and again at a reboot): nil, or an Event of
	// addBoard's arguments and the calibration (extFrictionDeviceBoard.sc).
	var <boardSetup;
	// The audio drive (extFrictionDeviceDrive.sc): (path:, circuitLatencyS:) once loaded, else nil.
	var <driveSetup;
	// watchClient's: the Routine sending the heartbeats, and its timeout (s; 0 no watch).
	var heartbeat, <clientTimeoutS = 0;

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

	// How long (s) a command waits for the server's answer (FrictionAnswers.timeout).
	*answerTimeout { ^FrictionAnswers.timeout }
	*answerTimeout_ { |seconds| FrictionAnswers.timeout = seconds }

	// The server of device: a FrictionDevice's (Server.default when it has none) or, for a slot
	// index, Server.default.
	*serverOf { |device|
		^if(device.isKindOf(FrictionDevice)) { device.server ? Server.default } { Server.default }
	}

	// server: a running Server (nil: Server.default). hand: a FrictionHand (nil: the puck stays
	// put). profile: an Event of spec or simulation settings by name (e.g. (maxForceN: 1.0,
	// puckMassKg: 0.2)); nil: the paper's numbers. replace: true closes a device open in the slot;
	// false (the default) refuses the slot.
	*sim { |server, index = 0, hand, profile, replace = false|
		^this.prSim(server ? Server.default, index, hand, profile, replace, "sim").prOpen
	}
	// The same device described only, on no server: its ...Msg methods for a Score.
	*describeSim { |index = 0, hand, profile, replace = false|
		^this.prSim(nil, index, hand, profile, replace, "describeSim")
	}

	// path: a kf-session recording (FrictionDevice.record) or a hid-recorder .hid file.
	*replay { |server, path, index = 0, profile, replace = false|
		path = this.prReplayPath(path, "replay");
		if(File.exists(path).not) { Error("FrictionDevice.replay: no such file: %".format(path)).throw };
		^this.new.prInit(server ? Server.default, index, \replay, path, profile, replace).prOpen
	}
	// Described only (for a Score, which may write the file before it plays it).
	*describeReplay { |path, index = 0, profile, replace = false|
		^this.new.prInit(nil, index, \replay, this.prReplayPath(path, "describeReplay"), profile, replace)
	}

	// A real mouse and the friction board with its calibration, opened as one device: one answer
	// for the whole (inside a Routine it waits and a refusal is an Error; elsewhere a refusal is
	// posted). When the board or its calibration is refused, the mouse opened for it is closed
	// again. mouse, profile, index, backend, grab: as FrictionDevice.mouse's which, profile...;
	// board: nil (the first board found), a serial String, or \emulate (the board emulator);
	// calibration: as calibrate takes it (a FrictionCalibration written to a file, a path, nil).
	// Why a sequence of the server's own commands (kfOpenMouse, kfBoardOpen, kfBoardCalibrate)
	// rather than one composite command: each part already answers with its own reason, and a
	// failed part is undone by one kfClose; a composite would repeat the mouse's and the board's
	// arguments and stages in the plugin for the same outcome. See ARCHITECTURE.md.
	*hardware { |server, mouse, board, profile, calibration, index = 0, backend, grab = false, replace = false|
		^this.new.prInitMouse(server ? Server.default, index, mouse, backend, profile, grab, replace)
		.prInitBoard(board, calibration, "FrictionDevice.hardware").prOpen
	}

	// The devices open (or opening) in sclang, on all servers.
	*all { ^slots.values.asArray.collect { |a| a.select(_.notNil) }.flatten(1) }
	// The device sclang holds in a slot of server, or nil.
	*at { |server, index| ^slots[server] !? { |a| a[index] } }

	isOpen { ^state == \open }

	// Audio is delayed by this much so that sound and touch arrive together: the paper's 1 ms, or
	// with an audio drive loaded (extFrictionDeviceDrive.sc) the drive's own latency.
	audioDelay { ^this.driveLatency ?? { specs[\tactileLatencyS] - specs[\audioLatencyS] } }

	// The plugin command that opens this kind of device.
	openCommand { ^(sim: \kfOpenSim, replay: \kfOpenReplay, mouse: \kfOpenMouse)[kind] }

	openMsg {
		^switch(kind,
			\mouse, { this.mouseMsg },  // extFrictionDeviceMouse.sc
			\sim, {
				['/cmd', \kfOpenSim, index] ++ (source !? { source.asCommandArgs } ?? { [-1, 0] })
				++ this.prOverrideArgs
			},
			{ ['/cmd', \kfOpenReplay, index, source] ++ this.prOverrideArgs }
		) ++ (if(replace) { [\replace, 1] } { [] })
	}

	// The puck's latest reported position becomes (x, y) mm for every reader of the device, from
	// the block the server executes the command in (a bundle's time, in a Score its time).
	zero { |x = 0, y = 0| this.prSendAnswered(\kfZero, this.zeroMsg(x, y)) }
	zeroMsg { |x = 0, y = 0|
		[\x, x, \y, y].pairsDo { |name, mm| FrictionCheck.finite(mm, name, "FrictionDevice.zero") };
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
			this.prStartBusSynths;
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
	// post: false asks for the /kfStatus reply only, nothing posted.
	statusMsg { |post = true| ^['/cmd', \kfStatus, index] ++ (if(post) { [] } { [0] }) }

	// The same figures as numbers: an Event (FrictionDevice.statusOf) passed to action, from the
	// server's /kfStatus reply to the clients registered with /notify (sclang by default).
	// Nothing is posted: polling it leaves the post window readable (status posts them).
	statusValues { |action|
		var reply;
		if(server.isNil) { ^this };
		FrictionCheck.serverRunning(server, "FrictionDevice.statusValues");
		reply = OSCFunc({ |msg| action.value(this.class.statusOf(msg[3..])) }, '/kfStatus', server.addr,
			argTemplate: [nil, index]).oneShot;
		// A refused or unanswered kfStatus sends no reply: its responder would wait for the next one.
		this.prSendAnswered(\kfStatus, this.statusMsg(false), onFail: { reply.free })
	}
	// Thread priorities: -1 no such thread, 0 normal scheduling (realtime refused or not asked
	// for), > 0 SCHED_FIFO. Durations in s, the force in N.
	*statusFields {
		^#[open, realtime, deviceThreadPriority, mouseThreadPriority, usbThreadPriority, memoryLocked, reports,
			frames, watchdogTrips, missedDeadlines, skippedFrames, lateFrames, reportQueueOverflows,
			frameQueueOverflows, loopP50S, loopP99S, loopMaxS, forceP50S, forceP99S, forceP999S, forceMaxS,
			reportP50S, reportP99S, reportMaxS, releaseLatencyS, reportIntervalS, reportJitterS, lastForceN, recording,
			audioCallMaxS, fault]
	}
	*statusOf { |values|
		var event = ();
		this.statusFields.do { |name, i| event[name] = values[i] };
		#[open, realtime, memoryLocked, recording].do { |name| event[name] = event[name] == 1 };
		event[\fault] = this.faultOf(event[\fault]);
		^event
	}
	// What of an open device failed, from the code in a /kfStatus reply: nil (nothing),
	// \threadStopped (a backend failed: nothing drives the device until it is opened again),
	// \mouseUnplugged, \boardNotConnected or \boardFault (the board tripped: over-current, power).
	*faultOf { |code| ^#[nil, \threadStopped, \mouseUnplugged, \boardNotConnected, \boardFault][code ? 0] }

	// A simulated realtime device's thread fails at once, as a driver that lost its device
	// would: the magnet off, the recording ended (cause failure), statusValues' fault
	// \threadStopped. To rehearse what a study or a set does when its device fails.
	simulateFailure { this.prSendAnswered(\kfSimFail, this.simulateFailureMsg) }
	simulateFailureMsg { ^['/cmd', \kfSimFail, index] }

	// A simulated device opened with (handHeld: true): its hand starts its movement now.
	releaseHand { this.prSendAnswered(\kfSimRelease, this.releaseHandMsg) }
	releaseHandMsg { ^['/cmd', \kfSimRelease, index] }

	// A 4-channel control Bus of the puck's [x, y, speedX, speedY] (mm, mm/s), made on first
	// use and written by one reader synth at the head of the server: for GUIs and re-centring
	// (positionBus.getn(4, action)); it comes back after Cmd-. and a reboot.
	positionBus {
		if(server.isNil) { Error("FrictionDevice.positionBus: the device has no server").throw };
		positionBus ?? {
			positionBus = Bus.control(server, 4);
			this.prStartBusSynths;
		};
		^positionBus
	}

	// Closes the device if this object still holds its slot (a device opened with replace: true
	// in the same slot is not closed by the object it replaced).
	close {
		if(server.isNil) { ^this };
		if(this.class.at(server, index) !== this) {
			"FrictionDevice: % does not hold slot % (closed or replaced); nothing to close".format(
				this, index).warn;
			^this
		};
		this.prForget(\closed);
		if(server.serverRunning) { this.prSendAnswered(\kfClose, this.closeMsg) };
	}
	closeMsg { ^['/cmd', \kfClose, index] }

	// The client watch: the server turns this device's force off (the magnet off, the off the
	// recording's last line until sclang is heard again) once sclang has sent no heartbeat for
	// timeoutS, as when sclang crashed or was killed with the synths still playing. sclang sends
	// one every timeoutS / 4 from now on (SystemClock), until watchClient(0), the device closes,
	// or Cmd-. stops the heartbeats' Routine (so Cmd-. also turns the force off, timeoutS later).
	// Off by default: SC's servers play on without their client, as a live coder may want. A
	// study session turns it on for its devices (FrictionStudySession.clientTimeoutS).
	watchClient { |timeoutS = 2|
		var where = "FrictionDevice.watchClient";
		FrictionCheck.finite(timeoutS, "timeoutS", where);
		if(timeoutS < 0 or: { timeoutS > 3600 }) { Error("%: timeoutS must be 0 to 3600 s, got %".format(where,
			timeoutS)).throw };
		if(this.isOpen.not) { Error("%: % is not open".format(where, this)).throw };
		heartbeat !? _.stop;
		heartbeat = nil;
		clientTimeoutS = timeoutS;
		server.listSendMsg(['/cmd', \kfHeartbeat, index, timeoutS.asFloat]);
		if(timeoutS > 0) {
			heartbeat = Routine {
				loop { (timeoutS / 4).wait; server.listSendMsg(['/cmd', \kfHeartbeat, index]) }
			}.play(SystemClock)
		}
	}

	printOn { |stream| stream << this.class.name << "(" << kind << ", " << index << ")" }

	// A device stands for its slot wherever a UGen input or a synth argument wants one, as a
	// Buffer stands for its bufnum: FrictionMouseIn.ar(~device), Synth(\x, [\device, ~device]).
	asUGenInput { ^index }
	asControlInput { ^index }

	*prSim { |server, index, hand, profile, replace, method|
		if(hand.notNil and: { hand.isKindOf(FrictionHand).not }) {
			Error("FrictionDevice.%: hand must be a FrictionHand or nil, got %".format(method, hand)).throw
		};
		^this.new.prInit(server, index, \sim, hand, profile, replace)
	}

	*prReplayPath { |path, method|
		if(path.isString.not) { Error("FrictionDevice.%: path must be a String, got %".format(method, path)).throw };
		^path.standardizePath
	}

	// kind: \sim, \replay or \mouse, the class method that opens it (and names its errors).
	prInit { |argServer, argIndex, argKind, argSource, profile, argReplace = false|
		var where = "FrictionDevice." ++ argKind;
		replace = FrictionCheck.boolean(argReplace, "replace", where);
		if(argIndex.isInteger.not or: { argIndex < 0 or: { argIndex > 15 } }) {
			Error("%: index must be an Integer from 0 to 15, got %".format(where, argIndex)).throw
		};
		if(profile.notNil and: { profile.isKindOf(Dictionary).not }) {
			Error("%: profile must be an Event of settings, got %".format(where, profile)).throw
		};
		server = argServer;
		index = argIndex;
		busSynths = IdentityDictionary.new;
		kind = argKind;
		source = argSource;
		overrides = ();
		(profile ? ()).keysValuesDo { |key, value|
			if(value == true or: { value == false }) { value = value.binaryValue };  // loop: true
			if(value.isNumber.not) {
				Error("%: setting % must be a number, got %".format(where, key, value)).throw
			};
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
		FrictionCheck.serverRunning(server, "FrictionDevice." ++ kind);
		state = \opening;
		// The server decides whether the slot is free (or replaced): it holds the devices of
		// every client. Its answer updates what sclang holds.
		FrictionAnswers.sendSequence(server, index, this.prOpenSteps, {
			this.prHold;
		}, { |reason, step|
			state = \failed;
			this.prUndoOpen(step)
		});
	}

	// The commands that open the device: the open, then its board and calibration if it has one.
	prOpenSteps {
		^[[this.openCommand, this.openMsg]] ++ (boardSetup !? { |b|
			[[\kfBoardOpen, this.addBoardMsg(b[\serial], b[\emulate], b[\inFlight])],
				[\kfBoardCalibrate, this.calibrateMsg(b[\calibration])]]
		} ? []) ++ (driveSetup !? { |d| [[\kfDriveCalibrate, this.loadDriveMsg(d[\path])]] } ? [])
	}

	// After step (of prOpenSteps) was refused: the device opened by the first is closed again (the
	// server runs commands in order, so one sent after this finds the slot free); what was undone.
	prUndoOpen { |step|
		if(step == 0) { ^nil };
		server.listSendMsg(this.closeMsg);
		// The open itself succeeded: the device sclang held in the slot was replaced on the server.
		this.class.at(server, index) !? { |previous| if(previous !== this) { previous.prForget(\replaced) } };
		^"the % device it opened in slot % was closed again".format(kind, index)
	}

	prHold {
		var previous = this.class.at(server, index);
		if(previous.notNil and: { previous !== this }) { previous.prForget(\replaced) };
		slots[server] = slots[server] ?? { Array.newClear(16) };
		slots[server][index] = this;
		state = \open;
		this.prStartBusSynths;
	}

	// Sends msg and awaits /kfDone or /kfFail for cmd on this slot (FrictionAnswers.send).
	prSendAnswered { |cmd, msg, onDone, onFail, block = true|
		FrictionAnswers.send(server, cmd, index, msg, onDone, onFail, block)
	}

	prForget { |newState|
		var held = slots[server], holdsBuses = state != \quit;
		heartbeat !? _.stop;
		heartbeat = nil;
		clientTimeoutS = 0;
		if(held.notNil and: { held[index] === this }) { held[index] = nil };
		state = newState;
		// A node may be gone already (s.freeAll just before): freed without the server's complaint.
		if(server.serverRunning and: { busSynths.notEmpty }) {
			server.sendBundle(nil, ['/error', -1], *busSynths.values.collect { |node| ['/n_free', node.nodeID] })
		};
		busSynths = IdentityDictionary.new;
		[forceBus, positionBus].do { |bus| if(holdsBuses and: { bus.notNil }) { bus.free } };
		forceBus = nil;
		positionBus = nil;
	}

	// The writer of forceBus (at the tail: it sends the sum played into the bus to the device)
	// and the reader of positionBus (at the head: the puck for every synth after it), each started
	// once its bus exists: one synth per role, claimed at once so that it is never started twice,
	// and let go when the server ends it (Cmd-., s.freeAll, a quit), so that ServerTree starts it
	// again, and only then.
	prStartBusSynths {
		[
			[\writer, forceBus, \addToTail, \kfForceWriter,
				{ FrictionOut.ar(\device.ir(0), In.ar(\bus.ir(0), 1)) }],
			[\reader, positionBus, \addToHead, \kfPositionReader,
				{ Out.kr(\bus.ir(0), FrictionMouseIn.kr(\device.ir(0))) }]
		].do { |spec|
			var role, bus, addAction, defName, graph, node;
			#role, bus, addAction, defName, graph = spec;
			if(bus.notNil and: { busSynths[role].isNil }) {
				node = Synth.basicNew(defName, server);
				busSynths[role] = node;
				node.onFree { if(busSynths[role] === node) { busSynths.removeAt(role) } };
				forkIfNeeded {
					SynthDef(defName, graph).add;
					FrictionSync.wait(server, where: "FrictionDevice %'s % synth".format(index, role));
					// Forgotten meanwhile (closed, quit, Cmd-.): not started.
					if(busSynths[role] === node) {
						server.sendMsg(*node.newMsg(RootNode(server), [\device, index, \bus, bus.index], addAction));
					};
				};
			};
		};
	}

	*prServerQuit { |srv|
		// The server closed them; they are opened again at the next boot.
		slots[srv] !? { |held| held.do { |dev| dev !? { dev.prQuit } } };
		FrictionAnswers.failAll(srv, "the server quit");
	}

	// One device that cannot be opened again never stops the others, nor the rest of SC's boot
	// sequence (ServerBoot functions run one after another: an error would leave the server
	// without its default group).
	*prServerBoot { |srv|
		slots[srv] !? { |held|
			held.do { |dev|
				dev !? {
					try { dev.prReopen } { |error|
						"FrictionDevice: % was not opened again after the boot: %".format(dev,
							error.errorString.replace("ERROR: ", "")).error;
						dev.prForget(\failed);
					}
				}
			}
		};
	}

	*prServerTree { |srv|
		slots[srv] !? { |held| held.do { |dev| dev !? { dev.prRestoreWriter } } };
	}

	// The server freed the nodes; SC's quit made new bus allocators, so the buses are no longer
	// held either (prForget must not free their numbers: they may be someone else's now).
	prQuit { state = \quit; busSynths = IdentityDictionary.new }

	prReopen {
		if(state != \quit) { ^this };
		// The same Bus objects get channels again from the new allocators, as JITLib's proxies do:
		// whoever holds forceBus or positionBus follows (their numbers may change), and nothing
		// allocated after the boot can share them. (Reserving the old numbers is not possible:
		// SC 3.13's ContiguousBlockAllocator:reserve ignores the audio allocator's offset.)
		[forceBus, positionBus].do { |bus| bus !? { bus.alloc } };
		state = \opening;
		FrictionAnswers.sendSequence(server, index, this.prOpenSteps, {
			state = \open;
			this.prStartBusSynths;
			// The new server's device has no client watch: given again (the heartbeats went on).
			if(clientTimeoutS > 0) { this.watchClient(clientTimeoutS) };
		}, { |reason, step|
			this.prForget(\failed);
			this.prUndoOpen(step)
		}, false);
	}

	// After Cmd-. or s.freeAll (their nodes ended) and after a boot: the force writer and the
	// position reader again, those not running (a re-open answered before ServerTree started them).
	prRestoreWriter {
		if(state == \open) { this.prStartBusSynths };
	}

	// In a ProxySpace (~dev = FrictionDevice.sim(s)), the proxy plays the puck's position and
	// speed [x, y, speedX, speedY] at control rate; ~dev.source is the device.
	prepareForProxySynthDef { ^{ FrictionMouseIn.kr(index) } }

	prOverrideArgs {
		// Sorted by name, but a lift's end after its start: the server takes them in order, and a
		// liftEndS before any liftStartS is refused.
		var pairs = overrides.asSortedArray;
		pairs = pairs.reject { |p| p[0] == \liftEndS } ++ pairs.select { |p| p[0] == \liftEndS };
		^pairs.flatten(1).collect { |v| if(v.isKindOf(Symbol)) { v.asString } { v } }
	}
}
