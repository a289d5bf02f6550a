// A ready-made threshold experiment on a FrictionDevice: two-interval forced choice trials whose
// levels a procedure (FrictionStaircase, FrictionQuestPlus, FrictionConstantStimuli) chooses.
// Each trial plays the reference and the target (the reference changed by the level) in two
// intervals, in an order drawn from the experiment's seed; the answer (which interval held the
// target) comes from the keys (1 or 2, a small window, or `answer` from code), the puck's
// buttons (left 1, right 2: FrictionButtons) or a model observer (FrictionObserver). The three
// experiments (FrictionThresholdStimuli): *force (a friction-level difference, N), *asynchrony
// (how late the sound may come after the force, ms) and *grating (a grating period difference, mm).
FrictionThreshold {
	var <kind, <procedure, <settings, <intervalS, <gapS, <seed;
	// false: with \keys, no window of its own; the answers come through `answer` (a study's window).
	var <>showKeysWindow = true;
	var rng, answered, givenAnswer, keysWindow, buttonsResponder, buttonsSynth, runSynth, runBuffer;

	// base: the reference's force (N) above which the target adds the level.
	*force { |procedure, baseForceN = 0.3, intervalS = 1.5, gapS = 0.5, seed|
		^this.new(\force, procedure, (baseForceN: baseForceN), intervalS, gapS, seed)
	}

	// The pilot's sound and friction (FrictionPilot.ar, mapping of Table 1): the reference with the
	// device's audioDelay (sound and touch together), the target with the sound level ms later.
	*asynchrony { |procedure, mapping = \mapping2, amp = 0.5, intervalS = 1.5, gapS = 0.5, seed|
		^this.new(\asynchrony, procedure,
			(samplesPerMm: FrictionCheck.samplesPerMm(mapping, "FrictionThreshold.asynchrony"), amp: amp),
			intervalS, gapS, seed)
	}

	// A grating (FrictionPattern.grating) of periodMm in the reference, periodMm + level in the target.
	*grating { |procedure, periodMm = 2, duty = 0.5, loForceN = 0.14, hiForceN = 0.8, intervalS = 1.5, gapS = 0.5,
		seed|
		^this.new(\grating, procedure, (periodMm: periodMm, duty: duty, loForceN: loForceN, hiForceN: hiForceN),
			intervalS, gapS, seed)
	}

	*new { |kind, procedure, settings, intervalS = 1.5, gapS = 0.5, seed|
		^super.new.prInit(kind, procedure, settings, intervalS, gapS, seed)
	}

	prInit { |argKind, argProcedure, argSettings, argIntervalS, argGapS, argSeed|
		var where = "FrictionThreshold";
		if(FrictionThresholdStimuli.kinds.includes(argKind).not) {
			Error("%: kind must be one of %, got %".format(where, FrictionThresholdStimuli.kinds, argKind)).throw
		};
		if(argProcedure.isKindOf(FrictionProcedure).not) {
			Error("%: procedure must be a FrictionProcedure (FrictionStaircase, FrictionQuestPlus, "
				"FrictionConstantStimuli or a subclass of one's own), got %".format(where, argProcedure)).throw
		};
		argSettings.keysValuesDo { |key, value| FrictionCheck.finite(value, key, where) };
		[\intervalS, argIntervalS, \gapS, argGapS].pairsDo { |name, s|
			FrictionCheck.finite(s, name, where);
			if(s <= 0) { Error("%: % must be > 0 s, got %".format(where, name, s)).throw }
		};
		kind = argKind;
		procedure = argProcedure;
		settings = argSettings;
		intervalS = argIntervalS;
		gapS = argGapS;
		seed = argSeed ?? { 2147483647.rand };
		rng = FrictionObserver.randomSource(seed);
	}

	// The hand of a simulated device that strokes back and forth over strokeMm at speedMmPerS
	// for durationS: the puck moves during every interval, as a participant's hand would.
	*hand { |durationS = 60, strokeMm = 40, speedMmPerS = 80|
		var strokeS = strokeMm / speedMmPerS;
		^FrictionHand.path(Array.fill((durationS / strokeS).ceil.asInteger + 1, { |i|
			[i * strokeS, if(i.odd) { strokeMm } { 0 }]
		}))
	}

	// Runs the trials until the procedure is finished, inside a Routine. answers: \keys, \buttons
	// or a FrictionObserver. onTrial: called with an Event per trial (trial, level, target (the
	// interval of the target, 1 or 2), answer, correct, startS, interval1S, interval2S, answerS:
	// s from the run's start). out: the first of two output channels (the asynchrony's sound).
	// Returns the procedure's estimate (and passes it to onEnd).
	run { |device, answers = \keys, onTrial, onEnd, out = 0|
		var where = "FrictionThreshold.run", server, def, loaded, startS, level, estimate;
		if(thisThread.isKindOf(Routine).not) { Error("%: call it inside a Routine (fork)".format(where)).throw };
		if(device.isKindOf(FrictionDevice).not) {
			Error("%: device must be a FrictionDevice, got %".format(where, device)).throw
		};
		if(answers != \keys and: { answers != \buttons } and: { answers.isKindOf(FrictionObserver).not }) {
			Error("%: answers must be \\keys, \\buttons or a FrictionObserver, got %".format(where, answers)).throw
		};
		server = FrictionCheck.serverRunning(device.server, where);
		this.checkRange(device.specs, device);
		def = FrictionThresholdStimuli.synthDef(kind, device, settings).add;
		if(kind == \asynchrony) {
			// The signal is sent in parts: the run starts once all of it is on the server.
			loaded = Condition(false);
			runBuffer = FrictionPilot.loadSignal(server, { loaded.test = true; loaded.signal });
			loaded.wait
		};
		answered = Condition(false);
		this.prStartAnswers(answers, device);
		FrictionSync.wait(server, where: where);
		server.bind { runSynth = Synth(def.name, [\out, out, \bufnum, runBuffer !? _.bufnum ? 0,
			\intervalS, intervalS, \gapS, gapS]) };
		startS = thisThread.seconds;
		// On any way out, a refused force or onTrial's Error included, nothing of the run stays.
		protect { while { (level = procedure.next).notNil } {
			var target = rng.next({ [1, 2].choose }), trial, t;
			this.prCheckForces(device.specs, [level], device);
			this.prCatchUp(server);
			t = thisThread.seconds - startS;
			trial = (trial: procedure.trials.size + 1, level: level, target: target, startS: t, interval1S: t,
				interval2S: t + intervalS + gapS);
			// One bundle: the server plays both intervals (FrictionThresholdStimuli.trialControls).
			server.bind { runSynth.set(\level1, if(target == 1) { level } { 0 },
				\level2, if(target == 2) { level } { 0 }, \trial, 1) };
			// The answer is taken once both intervals played (server.latency after the bundle was
			// sent) and the gap after them passed.
			this.prWaitS(2 * intervalS + gapS + max(gapS, server.latency ? 0));
			trial[\answer] = this.prAwaitAnswer(answers, level, target);
			trial[\answerS] = thisThread.seconds - startS;
			trial[\correct] = trial[\answer] == target;
			procedure.respond(level, trial[\correct]);
			onTrial.value(trial)
		} } { this.stop };
		// The bundles play server.latency after they are sent: the synth is gone when run returns.
		this.prWaitS(server.latency ? 0);
		estimate = procedure.estimate;
		onEnd.value(estimate);
		^estimate
	}

	// A trial's bundle is stamped server.latency after sclang's logical time. If sclang stood still
	// longer than half of that (a garbage collection, a long evaluation, a loaded machine), the
	// trial would start late at the server, after the start its Event says, maybe while the trial
	// before still plays: the logical time catches up with the clock's first. (AppClock's logical
	// time is when it woke the routine: a wait of 0 brings it to now. With no latency the bundles
	// have no time stamp.)
	prCatchUp { |server|
		var lateS = Main.elapsedTime - thisThread.seconds;
		if(server.latency.notNil and: { lateS > (server.latency / 2) }) {
			if(thisThread.clock === AppClock) { 0.wait } { this.prWaitS(lateS) }
		}
	}

	// Waits s seconds on the clock of the Routine run runs in, whatever its tempo.
	prWaitS { |s| (thisThread.clock.secs2beats(thisThread.seconds + s) - thisThread.beats).wait }

	// Continues from trials stored by an earlier run (a session that crashed and is resumed): an
	// Array of Events with level and correct (Booleans, or "true"/"false" as trials.csv holds
	// them), in their order. Each is given to the procedure as the answer to the level it asks,
	// the interval order drawn as the run would, and observer (a FrictionObserver, or nil) skips
	// its answer; run then goes on from the next trial, numbered on. The procedure must ask each
	// stored level in turn (same procedure, same seed): else an Error says at which trial they part.
	continueFrom { |trials, observer|
		var where = "FrictionThreshold.continueFrom";
		if(procedure.trials.notEmpty) { Error("%: the procedure has run trials already".format(where)).throw };
		trials.do { |stored, i|
			var asked = procedure.next, level = stored[\level], correct = stored[\correct];
			if(level.isString) { level = level.asFloat };
			if(correct.isString) { correct = correct == "true" };
			FrictionCheck.boolean(correct, "correct", where);
			if(asked.isNil or: { level.isNumber.not } or: { (asked - level).abs > (1e-9 * max(1, asked.abs)) }) {
				Error(("%: trial % was stored at level %, where the procedure asks % (not the procedure, or not "
					"the seed, that stored it)").format(where, i + 1, level, asked)).throw
			};
			rng.next({ [1, 2].choose });
			procedure.respond(asked, correct);
			observer !? { observer.skip(1) }
		}
	}

	// The force experiment's reference and targets must be forces the device renders: one outside
	// its minForceN..maxForceN would be clamped, and both intervals could hold the same force.
	// checkRange checks every level the procedure can name (its levelRange; infinite ends are left
	// to the trials) against specs (a device's; FrictionDevice.paperSpecs for a simulated one):
	// run does before the first trial, a study session for each threshold condition when it
	// starts. run checks each trial's level too. An Error with the reason; what: the device named.
	checkRange { |specs, what = "the device"|
		this.prCheckForces(specs, procedure.levelRange, what)
	}

	prCheckForces { |specs, levels, device|
		var lo, hi, base = settings[\baseForceN];
		if(kind != \force) { ^this };
		lo = specs[\minForceN];
		hi = specs[\maxForceN];
		([0] ++ levels.reject { |l| l.abs == inf }).do { |level|
			var force = base + level;
			if(force.isNaN or: { force < (lo - 1e-9) } or: { force > (hi + 1e-9) }) {
				Error(("FrictionThreshold.force: % N (the reference % N + the level %) is outside the % N to % N "
					"that % renders: it would be clamped, and both intervals could hold the same force").format(
					force, base, level, lo, hi, device)).throw
			}
		};
	}

	// The answer of the trial waiting for one: which interval (1 or 2) held the target. The keys'
	// window and the buttons call it; so may any window of a study.
	answer { |interval|
		if(interval != 1 and: { interval != 2 }) {
			Error("FrictionThreshold.answer: interval must be 1 or 2, got %".format(interval)).throw
		};
		if(answered.notNil and: { answered.test.not }) {
			givenAnswer = interval;
			answered.test = true;
			answered.signal
		}
	}

	prAwaitAnswer { |answers, level, target|
		if(answers.isKindOf(FrictionObserver)) { ^if(answers.answer(level)) { target } { 3 - target } };
		answered.test = false;
		givenAnswer = nil;
		answered.wait;
		^givenAnswer
	}

	prStartAnswers { |answers, device|
		switch(answers,
			\keys, {
				if(showKeysWindow) { defer {
					keysWindow = Window("Which interval? 1 or 2", Rect(100, 100, 320, 80)).front;
					StaticText(keysWindow, keysWindow.view.bounds.insetBy(10)).string_(
						"Press 1 if the first interval was the different one, 2 if the second.");
					keysWindow.view.keyDownAction = { |view, char|
						case { char == $1 } { this.answer(1) } { char == $2 } { this.answer(2) }
					}
				} }
			},
			\buttons, {
				buttonsResponder = OSCFunc({ |msg| this.answer(msg[3].asInteger) }, '/kfThresholdButton',
					device.server.addr);
				buttonsSynth = { FrictionThresholdStimuli.buttonsReply(device) }.play(device.server)
			}
		)
	}

	// Ends what a run started (its stimulus, the signal's buffer, the answers' window and
	// responders), each once: run does it on any way out; call it when run's Routine was stopped.
	stop {
		var synth = runSynth, buffer = runBuffer, server = (runSynth ? runBuffer) !? _.server;
		runSynth = runBuffer = nil;
		this.prStopAnswers;
		// One bundle, server.latency from now: the buffer goes with the synth that reads it. Its
		// number goes back to sclang's allocator once the server has freed it (the bundle's /sync
		// answered): Buffer.free gives it back at once, and a buffer allocated before the bundle ran
		// (in a study, another session's recording, side by side) got it and was freed by the bundle.
		server !? {
			Routine {
				server.sync(nil, [synth !? { synth.freeMsg }, buffer !? { [\b_free, buffer.bufnum] }].select(_.notNil),
					server.latency);
				buffer !? { buffer.uncache; server.bufferAllocator.free(buffer.bufnum) };
			}.play(SystemClock)
		}
	}

	prStopAnswers {
		keysWindow !? { |w| defer { w.close } };
		buttonsResponder !? _.free;
		buttonsSynth !? _.free;
		keysWindow = buttonsResponder = buttonsSynth = nil
	}

	asEvent {
		^(kind: kind, settings: settings, intervalS: intervalS, gapS: gapS, seed: seed, procedure: procedure.asEvent)
	}
}
