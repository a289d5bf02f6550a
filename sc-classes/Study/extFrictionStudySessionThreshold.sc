// FrictionStudySession's threshold conditions: the experiment's trials into trials.csv, a resumed
// attempt continuing from the trials stored before, and every condition's stimuli checked against
// the device when the session starts.
+ FrictionStudySession {
	// A threshold condition: the experiment's trials (each a line of trials.csv, flushed), its
	// estimate in the events, then the questions. The experiment plays on the participant's pair. A
	// simulated participant answers through the condition's makeObserver, or its own observer for
	// the experiment's kind; the experiment and the observer (its known threshold) are logged.
	prRunThreshold {
		var estimate, how, stored, right = 0, count = 0;
		experiment = condition.makeExperiment.value;
		how = if(simulated.notNil) {
			condition.makeObserver !? { |make| make.value(simulated.seed) } ?? {
				simulated.observerFor(experiment.kind)
			}
		} { condition.answers };
		this.log(\experiment, FrictionStudyFiles.json(experiment.asEvent));
		if(how.isKindOf(FrictionObserver)) { this.log(\observer, FrictionStudyFiles.json(how.asEvent)) };
		// A resumed attempt goes on from the trials stored before: the procedure (and a simulated
		// participant's observer) as it was when the session stopped.
		stored = this.prStoredTrials;
		if(stored.notEmpty) {
			experiment.continueFrom(stored, if(how.isKindOf(FrictionObserver)) { how });
			count = stored.size;
			right = stored.count { |t| t[\correct] == "true" };
			this.log(\continue, this.prJoined(stored))
		};
		listenSynth = Synth.tail(server, \frictionStudyListen, [\in, participantOut, \out, experimenterOut]);
		this.prRecordAudio;
		participantWindow !? {
			participantWindow.showInstruction(condition.instruction);
			participantWindow.doneButton.visible = false;  // the experiment ends it
		};
		experimenterWindow !? { experimenterWindow.refresh };
		this.prStartRunning;
		estimate = experiment.run(conditionDevice, how, { |trial|
			// Stored once the server has answered since the trial ended (a round trip: a few ms): a
			// trial that ended on a lost server is never stored (prLost ends the session meanwhile;
			// with no answer in lostAfterS, FrictionSync's Error fails it).
			FrictionSync.wait(server, lostAfterS, "FrictionStudySession % after trial %".format(participant,
				trial[\trial]));
			// sclang stood still during the trial (the watch did not tick): its times are not the
			// participant's; it is not stored, whichever of the two routines runs first after it.
			this.prStoodStill !? { |reason| this.prLost(reason) };
			FrictionStudyFiles.appendCsv(folder +/+ "trials.csv", [participant, position + 1, condition.name, attempt]
				++ #[trial, level, target, answer, correct, startS, interval1S, interval2S, answerS].collect { |k|
					trial[k] } ++ [FrictionStudyFiles.now], trialsHeader);
			this.log(\trial, trial[\trial]);
			count = count + 1;
			if(trial[\correct] == true) { right = right + 1 };
		}, nil, participantOut);
		endedBy = \procedure;
		this.log(\done, \procedure);
		this.log(\estimate, FrictionStudyFiles.json(estimate));
		stats = (trials: count, correct: right);
		state = \stopping;
		this.prStopAudio;
		listenSynth.free;
		listenSynth = nil;  // freed once (prFreeAfterFailure)
		this.prSync;
		conditionDevice.stopRecording;
		if(simulated.notNil) { conditionDevice.close };
		this.prSync;
		^this.prQuestions
	}

	// The trials an earlier attempt at this threshold condition stored, which this attempt goes on
	// from: per trial number the row of the latest attempt that has it, from trial 1 to the first
	// number none has (a damaged row: the procedure goes on from there). The report joins them so.
	prStoredTrials {
		var mine, byTrial = (), n = 1, stored = [];
		if(attempt < 2) { ^[] };
		mine = FrictionStudyFiles.readCsv(folder +/+ "trials.csv").select { |t|
			t[\position] == (position + 1).asString and: { t[\condition] == condition.name.asString }
		};
		mine.sort { |a, b| a[\attempt].asInteger <= b[\attempt].asInteger }.do { |t| byTrial[t[\trial].asInteger] = t };
		while { byTrial[n].notNil } { stored = stored.add(byTrial[n]); n = n + 1 };
		^stored
	}

	// How stored trials join: "1-8 of attempt 1, 9-12 of attempt 2".
	prJoined { |stored|
		var parts = stored.separate { |a, b| a[\attempt] != b[\attempt] };
		^parts.collect { |p| "%-% of attempt %".format(p.first[\trial], p.last[\trial], p.first[\attempt]) }.join(", ")
	}

	// Every threshold condition's stimuli against the device's range before the session starts
	// (FrictionThreshold.checkRange): a level the device would clamp is refused now, not when its
	// condition comes. The simulated participant's devices have the paper's specs.
	prCheckStimuli {
		var specs = device !? _.specs ?? { FrictionDevice.paperSpecs };
		order.select(_.isThreshold).do { |c|
			try { c.makeExperiment.value.checkRange(specs, device ? "the simulated device") } { |error|
				Error("FrictionStudy: condition %: %".format(c.name, error.what)).throw
			}
		}
	}
}
