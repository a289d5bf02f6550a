// The paper's pilot interaction (section 3, Table 1): a 1D signal laid out on the surface is
// read by the puck's position (FrictionMouseIn -> SpatialBufRd), heard (delayed by the
// device's audioDelay so sound and touch arrive together) and felt (LoudnessToFriction ->
// FrictionOut), on one device slot. Positions in mm, times in s, forces in N.
FrictionPilot {
	classvar <mappings, <signalFrames, <cycleFrames;
	classvar <paperLoForceN, <paperHiForceN, <paperAudioDelayS;
	// The heard sound's DC blocker (Hz): a resting puck's constant decays with a time constant of
	// 1 / (2 pi 5) = 32 ms; above 20 Hz, where hearing starts, the loss is under 0.3 dB.
	classvar <dcBlockerHz = 5;
	classvar <recordChannelNames;

	var <device, <mapping, <samplesPerMm, <friction, <origin, <amp, <out;
	var <buffer, <synth, <defName, monitorBus, monitorAllocator, quitAction;

	*initClass {
		var pilot = KineticFriction.paperPilot, mapping = KineticFriction.paperMapping;
		// Table 1: samples per mm of the three mappings.
		mappings = (mapping1: pilot[\mapping1SamplesPerMm], mapping2: pilot[\mapping2SamplesPerMm],
			mapping3: pilot[\mapping3SamplesPerMm]);
		signalFrames = pilot[\signalFrames];
		cycleFrames = pilot[\cycleFrames];
		paperLoForceN = mapping[\loForceN];
		paperHiForceN = mapping[\hiForceN];
		paperAudioDelayS = KineticFriction.paperDevice.use { ~tactileLatencyS - ~audioLatencyS };
		// What the recording outputs carry, in this order, from recordBus on.
		recordChannelNames = [\positionMm, \speedMmPerS, \audio, \delayedAudio, \requestedForceN, \commandedForceN];
	}

	// ---- the pilot signal and the mappings ----

	// The pilot signal: a sine of amplitude 1, 240 cycles of 100 samples (24000 samples).
	*signal {
		^Signal.fill(signalFrames, { |i| sin(2pi * i / cycleFrames) })
	}

	// Loads the pilot signal into a new Buffer on server (any server: sent as /b_setn once the
	// buffer is allocated, which FrictionSync waits for, bounded, where Buffer.sendCollection's
	// server.sync would wait for ever on a lost answer). action: called with the buffer once all
	// of it is sent (the server takes it in order, before anything sent after).
	*loadSignal { |server, action|
		var buffer;
		server = server ? Server.default;
		if(server.isKindOf(Server).not) {
			Error("FrictionPilot.loadSignal: server must be a Server, got %".format(server)).throw
		};
		FrictionCheck.serverRunning(server, "FrictionPilot.loadSignal");
		buffer = Buffer(server, signalFrames, 1);
		forkIfNeeded {
			server.listSendMsg(buffer.allocMsg);
			FrictionSync.wait(server, where: "FrictionPilot.loadSignal");
			this.loadSignalMsgs(buffer.bufnum).drop(1).do { |msg| server.listSendMsg(msg) };
			action.value(buffer)
		};
		^buffer
	}

	// The OSC messages that put a signal (default: the pilot signal) into buffer bufnum, for a Score.
	*loadSignalMsgs { |bufnum = 0, signal|
		var msgs, chunk = 1024;
		signal = signal ? this.signal;
		this.prCheckBufnum(bufnum, "loadSignalMsgs");
		if(signal.isSequenceableCollection.not or: { signal.isEmpty } or: { signal.any { |v| v.isNumber.not } }) {
			Error("FrictionPilot.loadSignalMsgs: signal must be a non-empty array of numbers").throw
		};
		msgs = [['/b_alloc', bufnum, signal.size, 1]];
		(0, chunk .. signal.size - 1).do { |start|
			var part = signal.copyRange(start, min(start + chunk, signal.size) - 1);
			msgs = msgs.add(['/b_setn', bufnum, start, part.size] ++ part.asArray)
		};
		^msgs
	}

	// Samples per mm of a mapping: a name of Table 1 (\mapping1, \mapping2, \mapping3) or any
	// positive finite number of samples per mm.
	*samplesPerMmOf { |mapping| ^FrictionCheck.samplesPerMm(mapping, "FrictionPilot.samplesPerMmOf") }

	// Table 1 computed from samples per mm: cycle width and fragment width (mm), and the audio
	// frequency range (Hz) at the device's slowest and fastest speed (mm/s).
	*table { |mapping = \mapping1, minSpeed = 2.6, maxSpeed = 334|
		var spm = FrictionCheck.samplesPerMm(mapping, "FrictionPilot.table");
		^(
			samplesPerMm: spm,
			cycleWidthMm: cycleFrames / spm,
			fragmentWidthMm: signalFrames / spm,
			loHz: this.frequencyAt(minSpeed, spm),
			hiHz: this.frequencyAt(maxSpeed, spm)
		)
	}

	// The audio frequency (Hz) when the pilot signal is crossed at speed (mm/s).
	*frequencyAt { |speedMmPerS, mapping = \mapping1|
		^speedMmPerS.abs * FrictionCheck.samplesPerMm(mapping, "FrictionPilot.frequencyAt") / cycleFrames
	}

	// ---- the ugen graph ----

	// The mechanism as a ugen graph, for use inside any SynthDef. Returns an Event of audio-rate
	// signals: position (mm), speed (mm/s), audio (as read), delayedAudio (what to play: audio *
	// amp delayed by audioDelay), force (N, requested: loForceN + friction * (loudness mapping -
	// loForceN)) and commandedForce (N, FrictionOut's output: the last completed 1 ms frame).
	// friction 0 keeps the magnet at loForceN (use the device's minimum, 0.14 N for the paper).
	// amp scales only what is heard; the force follows the signal as read (amplitude 1 = 0 dB).
	*ar { |device = 0, bufnum = 0, samplesPerMm = 4000, origin = 0, friction = 1, amp = 1,
		audioDelay, loForceN, hiForceN, maxAudioDelay = 0.05, keep = 0|
		var mouse, audio, loudness, force, commanded, delayed;
		audioDelay = audioDelay ? paperAudioDelayS;
		loForceN = loForceN ? paperLoForceN;
		hiForceN = hiForceN ? paperHiForceN;
		[\samplesPerMm, samplesPerMm, \origin, origin, \friction, friction, \amp, amp,
			\loForceN, loForceN, \hiForceN, hiForceN].pairsDo { |name, value|
			if(value.isNumber and: { value.isNaN or: { value.abs == inf } }) {
				Error("FrictionPilot.ar: % must be finite, got %".format(name, value)).throw
			}
		};
		if(samplesPerMm.isNumber and: { samplesPerMm <= 0 }) {
			Error("FrictionPilot.ar: samplesPerMm must be > 0, got %".format(samplesPerMm)).throw
		};
		if(maxAudioDelay.isNumber.not or: { maxAudioDelay <= 0 }) {
			Error("FrictionPilot.ar: maxAudioDelay is fixed at build time and must be a number > 0 s, got %".format(
				maxAudioDelay)).throw
		};
		if(audioDelay.isNumber and: { audioDelay < 0 or: { audioDelay > maxAudioDelay } }) {
			Error("FrictionPilot.ar: audioDelay must be within [0, %] s, got %".format(maxAudioDelay, audioDelay)).throw
		};
		mouse = FrictionMouseIn.ar(device, 0, 1);
		audio = SpatialBufRd.ar(1, bufnum, mouse[0], samplesPerMm, origin, 4, keep);
		// Equations (1) and (2): 1 ms mean |a| -> dB -> [-30, 0] dB onto [lo, hi] N.
		loudness = LoudnessToFriction.ar(audio, loForce: loForceN, hiForce: hiForceN);
		force = loForceN + (friction.clip(0, 1) * (loudness - loForceN));
		commanded = FrictionOut.ar(device, force);
		// Audio latency 1.4 ms, tactile 2.4 ms: audio waits the difference (1 ms). What is heard
		// passes a DC blocker: a puck resting on the fragment reads one sample again and again, a
		// constant no speaker should get. The force is computed before it, from the signal as read.
		delayed = LeakDC.ar(DelayL.ar(audio * amp, maxAudioDelay, audioDelay), this.prDcBlockerCoef);
		^(position: mouse[0], speed: mouse[2], audio: audio, delayedAudio: delayed,
			force: force, commandedForce: commanded)
	}

	// LeakDC's coefficient for a cutoff of dcBlockerHz at the server's sample rate (a 1-pole
	// high-pass: y = x - x1 + coef * y1, coef = exp(-2 pi fc / sr)).
	*prDcBlockerCoef { ^exp(-2pi * dcBlockerHz * SampleDur.ir) }

	// A SynthDef of the pilot for device (a FrictionDevice or a slot index). Controls: device,
	// bufnum, samplesPerMm, origin (mm), friction (0 off .. 1 on), amp, out (stereo), audioDelay
	// (s, default the device's), and with record: true, recordBus: 6 audio channels from there
	// (see recordChannelNames).
	// monitor: true adds a control bus output (monitorBus: 5 channels) for FrictionView.
	*synthDef { |name = \frictionPilot, device = 0, record = false, loForceN, hiForceN, monitor = false|
		var index = FrictionCheck.deviceIndex(device, "FrictionPilot.synthDef");
		var delay = this.prAudioDelay(device);
		var lo = loForceN ?? { this.prMinForce(device) };
		var hi = hiForceN ? paperHiForceN;
		if(name.isKindOf(Symbol).not and: { name.isString.not }) {
			Error("FrictionPilot.synthDef: name must be a Symbol, got %".format(name)).throw
		};
		FrictionCheck.boolean(record, "record", "FrictionPilot.synthDef");
		[\loForceN, lo, \hiForceN, hi].pairsDo { |key, value|
			FrictionCheck.finite(value, key, "FrictionPilot.synthDef")
		};
		if(hi <= lo) {
			Error("FrictionPilot.synthDef: hiForceN (%) must be above loForceN (%)".format(hi, lo)).throw
		};
		^SynthDef(name.asSymbol, {
			var p = this.ar(\device.kr(index), \bufnum.kr(0), \samplesPerMm.kr(4000), \origin.kr(0),
				\friction.kr(1), \amp.kr(0.5), \audioDelay.kr(delay), lo, hi, max(0.05, delay), \keep.kr(0));
			Out.ar(\out.kr(0), p[\delayedAudio] ! 2);
			if(record) {
				Out.ar(\recordBus.kr(2),
					[\position, \speed, \audio, \delayedAudio, \force, \commandedForce].collect { |key| p[key] })
			};
			// Position, speed, requested and commanded force once per control block, and 1 while
			// running (the buffer is loaded before the synth starts).
			if(monitor == true) {
				Out.kr(\monitorBus.kr(0),
					A2K.kr([p[\position], p[\speed], p[\force], p[\commandedForce]]) ++ [DC.kr(1)])
			};
		})
	}

	// ---- Scores (NRT) ----

	// A Score that renders the pilot for device (a FrictionDevice, usually FrictionDevice.describeSim(
	// index, hand) or .describeReplay(path)): opens it, loads the signal, plays the pilot with
	// mapping (a name of Table 1 or samples per mm) and friction (0 off, 1 on) for duration s,
	// then closes the device. Output channels 0, 1: the delayed audio (times amp); with
	// recordBus (e.g. 2), 6 more channels (recordChannelNames). recordPath: also write a
	// kf-session recording of the device. duration nil: the hand script's duration + 0.5 s.
	*score { |device, mapping = \mapping1, friction = 1, duration, origin = 0, amp = 1,
		recordBus, recordPath, bufnum = 0, signal, nodeID = 1000|
		var spm = FrictionCheck.samplesPerMm(mapping, "FrictionPilot.score"), def, msgs;
		if(device.isKindOf(FrictionDevice).not) {
			Error("FrictionPilot.score: device must be a FrictionDevice (e.g. FrictionDevice.describeSim(0, hand)), "
				"got %".format(device)).throw
		};
		duration = duration ?? {
			if(device.kind == \sim and: { device.source.notNil }) { device.source.duration + 0.5 } {
				Error("FrictionPilot.score: give a duration (s) for %".format(device)).throw
			}
		};
		if(duration.isNumber.not or: { duration.isNaN } or: { duration <= 0 } or: { duration == inf }) {
			Error("FrictionPilot.score: duration must be a positive finite number (s), got %".format(duration)).throw
		};
		this.prCheckFriction(friction, "score");
		FrictionCheck.finite(origin, "origin", "FrictionPilot.score");
		FrictionCheck.finite(amp, "amp", "FrictionPilot.score");
		if(recordBus.notNil and: { recordBus.isInteger.not or: { recordBus < 2 } }) {
			Error("FrictionPilot.score: recordBus must be nil or an Integer >= 2 (0 and 1 carry the audio), "
				"got %".format(recordBus)).throw
		};
		if(recordPath.notNil and: { recordPath.isString.not }) {
			Error("FrictionPilot.score: recordPath must be nil or a String, got %".format(recordPath)).throw
		};
		def = this.synthDef(\frictionPilot, device, recordBus.notNil);
		msgs = [[0.0, device.openMsg]];
		if(recordPath.notNil) { msgs = msgs.add([0.0, device.recordMsg(recordPath)]) };
		msgs = msgs ++ this.loadSignalMsgs(bufnum, signal).collect { |m| [0.0, m] };
		msgs = msgs.add([0.0, ['/d_recv', def.asBytes]]);
		msgs = msgs.add([0.0, ['/s_new', \frictionPilot, nodeID, 0, 0,
			\bufnum, bufnum, \samplesPerMm, spm, \origin, origin, \friction, friction, \amp, amp]
			++ (recordBus !? { [\recordBus, recordBus] } ? [])]);
		if(recordPath.notNil) { msgs = msgs.add([duration, device.stopRecordingMsg]) };
		msgs = msgs.add([duration, ['/n_free', nodeID]]);
		msgs = msgs.add([duration, device.closeMsg]);
		^Score(msgs)
	}

	// Switching a running pilot: the OSC messages for a node (Score or realtime).
	*setMappingMsg { |nodeID, mapping|
		^['/n_set', nodeID, \samplesPerMm, FrictionCheck.samplesPerMm(mapping, "FrictionPilot.setMappingMsg")]
	}
	*setFrictionMsg { |nodeID, on| ^['/n_set', nodeID, \friction, this.prCheckFriction(on, "setFrictionMsg")] }

	// ---- realtime ----

	// A pilot on a running server: FrictionPilot(device).play; then .mapping_(\mapping2),
	// .friction_(0), .free. device: a FrictionDevice (its server is used) or a slot index (on
	// Server.default).
	*new { |device, mapping = \mapping1, friction = 1, origin = 0, amp = 0.5, out = 0|
		^super.new.prInit(device, mapping, friction, origin, amp, out)
	}

	server { ^FrictionDevice.serverOf(device) }

	// The delay of the pilot's sound (s): the device's audioDelay, which an audio drive sets
	// (FrictionDevice.loadDrive), else the paper's 1 ms.
	audioDelay { ^this.class.prAudioDelay(device) }

	play {
		var server = this.server;
		FrictionCheck.serverRunning(server, "FrictionPilot.play");
		if(synth.notNil) { ^this };
		defName = ("frictionPilot" ++ FrictionCheck.deviceIndex(device, "FrictionPilot.play")).asSymbol;
		// The synth is claimed now, so that a second play does nothing and a free before it starts
		// (below) keeps it from starting at all.
		synth = Synth.basicNew(defName, server);
		// Cmd-. frees the synth (the buffer stays); a quit frees both: play starts again.
		CmdPeriod.add(this);
		quitAction ?? { quitAction = { synth = nil; buffer = nil }; ServerQuit.add(quitAction, server) };
		"FrictionPilot: the sound is delayed by % ms (%)".format((this.audioDelay * 1000).round(0.001),
			if(device.isKindOf(FrictionDevice) and: { device.driveSetup.notNil }) {
				"the audio drive: one block + the current source + the coil"
			} { "the tactile path's latency - the audio path's" }).postln;
		forkIfNeeded {
			var starting = synth;
			buffer = buffer ?? { this.class.loadSignal(server) };
			this.class.synthDef(defName, device, monitor: true).add;
			FrictionSync.wait(server, where: "FrictionPilot.play");
			if(synth === starting) {
				server.sendMsg(*synth.newMsg(server.defaultGroup, [\bufnum, buffer.bufnum,
					\samplesPerMm, samplesPerMm, \origin, origin, \friction, friction, \amp, amp, \out, out,
					\monitorBus, this.monitorBus.index]));
				// Freed by anyone (n_free, s.freeAll): forgotten, so that play starts it again.
				starting.onFree { if(synth === starting) { synth = nil } };
			};
		};
	}

	mapping_ { |newMapping|
		samplesPerMm = FrictionCheck.samplesPerMm(newMapping, "FrictionPilot.mapping_");
		mapping = newMapping;
		synth !? { synth.set(\keep, 0, \samplesPerMm, samplesPerMm) }
	}

	// Changes the mapping (a name of Table 1 or samples per mm) about the puck: the server moves
	// the layout so that the sample under the puck stays in place (SpatialBufRd's keep), at the
	// block the change takes effect. From then on origin_ changes keep it in place too; mapping_
	// goes back to the absolute layout.
	zoom { |newMapping|
		samplesPerMm = FrictionCheck.samplesPerMm(newMapping, "FrictionPilot.zoom");
		mapping = newMapping;
		synth !? { synth.set(\keep, 1, \samplesPerMm, samplesPerMm) }
	}

	friction_ { |on|
		friction = this.class.prCheckFriction(on, "friction_");
		synth !? { synth.set(\friction, friction) }
	}

	origin_ { |mm|
		origin = FrictionCheck.finite(mm, "origin", "FrictionPilot.origin_");
		synth !? { synth.set(\origin, origin) }
	}
	amp_ { |value|
		amp = FrictionCheck.finite(value, "amp", "FrictionPilot.amp_");
		synth !? { synth.set(\amp, amp) }
	}

	// Opens a FrictionView of this pilot (its own window; or in parent).
	view { |parent, bounds| ^FrictionView.pilot(this, parent, bounds) }

	// 5 control channels the playing synth writes (position mm, speed mm/s, requested force N,
	// commanded force N, 1 while running), for FrictionView. Kept for the pilot's life, so a
	// view keeps reading it across free and play. SC's quit (and a boot's login) makes new bus
	// allocators, which hold none of the old numbers: the same Bus gets channels again from the
	// new one, so that nothing allocated after a reboot shares them.
	monitorBus {
		var allocator = this.server.controlBusAllocator;
		if(monitorBus.isNil) { monitorBus = Bus.control(this.server, 5) } {
			if(monitorAllocator !== allocator) { monitorBus.alloc }
		};
		monitorAllocator = allocator;
		^monitorBus
	}

	isPlaying { ^synth.notNil }

	// Cmd-. has freed the synth: the pilot is stopped, and play starts it again.
	cmdPeriod { synth = nil; CmdPeriod.remove(this) }

	free {
		synth !? { synth.free };
		synth = nil;
		monitorBus !? { this.monitorBus.setn(0 ! 5) };
		CmdPeriod.remove(this);
		quitAction !? { ServerQuit.remove(quitAction, this.server) };
		quitAction = nil;
		buffer !? { buffer.free };
		buffer = nil;
	}

	printOn { |stream|
		stream << this.class.name << "(" << device << ", " << mapping.cs << ", friction: " << friction << ")"
	}

	prInit { |argDevice, argMapping, argFriction, argOrigin, argAmp, argOut|
		FrictionCheck.deviceIndex(argDevice, "FrictionPilot.new");
		device = argDevice;
		samplesPerMm = FrictionCheck.samplesPerMm(argMapping, "FrictionPilot.new");
		mapping = argMapping;
		friction = this.class.prCheckFriction(argFriction, "new");
		origin = FrictionCheck.finite(argOrigin, "origin", "FrictionPilot.new");
		amp = FrictionCheck.finite(argAmp, "amp", "FrictionPilot.new");
		if(argOut.isInteger.not or: { argOut < 0 }) {
			Error("FrictionPilot.new: out must be a bus index (Integer >= 0), got %".format(argOut)).throw
		};
		out = argOut;
	}

	// ---- checks (those other classes share too are FrictionCheck's) ----

	*prAudioDelay { |device|
		^if(device.isKindOf(FrictionDevice)) { device.audioDelay } { paperAudioDelayS }
	}

	*prMinForce { |device|
		^if(device.isKindOf(FrictionDevice)) { device.specs[\minForceN] } { paperLoForceN }
	}

	*prCheckFriction { |on, method|
		if(on == true) { ^1 };
		if(on == false) { ^0 };
		if(on.isNumber.not or: { on.isNaN } or: { on < 0 } or: { on > 1 }) {
			Error("FrictionPilot.%: friction must be 0 (off), 1 (on), a Boolean or a number in between, got %".format(
				method, on)).throw
		};
		^on
	}

	*prCheckBufnum { |bufnum, method|
		if(bufnum.isInteger.not or: { bufnum < 0 }) {
			Error("FrictionPilot.%: bufnum must be an Integer >= 0, got %".format(method, bufnum)).throw
		};
		^bufnum
	}
}
