// A simulated participant for a FrictionStudy, so that a study runs with no one at the device:
// in each condition it explores the fragment on the surface as the paper's subjects were asked
// to, from quite slow to fast (FrictionHand.explore: a push, so friction slows it where it is
// high), says it is done when the coverage criterion is met (or after its round of speeds), and answers
// the questions from what it met (its speeds and the friction measured in the condition). It
// answers a threshold condition's trials through a model observer of its own (observerFor).
// Its hand (strength, speeds, how fast it adapts) and its thresholds are drawn from seed: five
// seeds, five people.
FrictionStudySimParticipant {
	var <seed, <exploreS, <settings;

	// exploreS: how long it explores a condition at most (s); nil: as long as one sweep of the
	// strip at each of its speeds takes (the slowest sweep sets the time of each speed step).
	*new { |seed = 1, exploreS| ^super.newCopyArgs(seed, exploreS).prInit }

	// The strip it explores in condition (a FrictionStudyCondition): the part of the fragment on
	// the surface and 5 mm either side of it.
	stripMm { |condition| ^condition.areaMm + [-5, 5] }

	// The time at each speed step in condition (s).
	tierS { |condition|
		var strip = this.stripMm(condition);
		^if(exploreS.notNil) { exploreS / settings[\tiers] } { (strip[1] - strip[0]) / settings[\slowMmPerS] }
	}

	exploreSFor { |condition| ^this.tierS(condition) * settings[\tiers] }

	// The hand for condition: the strip, its speeds in tiers steps of tierS.
	handFor { |condition|
		var strip = this.stripMm(condition), s = settings;
		^FrictionHand.explore(strip[0], strip[1], s[\slowMmPerS], s[\fastMmPerS], s[\tiers],
			this.tierS(condition), s[\maxPushN], s[\gainNSPerM], s[\adaptS])
	}

	// Its model observer for a FrictionThreshold experiment of kind (\force, \asynchrony, \grating):
	// a FrictionObserver with its threshold for that kind (settings[\thresholds]), slope 3.5, lapse
	// 0.02, seeded from its seed and the kind.
	observerFor { |kind|
		var threshold = settings[\thresholds][kind];
		if(threshold.isNil) {
			Error("FrictionStudySimParticipant.observerFor: no threshold for %; kinds: %".format(kind.cs,
				settings[\thresholds].keys.asArray.sort)).throw
		};
		^FrictionObserver(threshold, 3.5, 0.02, seed: seed * 8 + FrictionThresholdStimuli.kinds.indexOf(kind))
	}

	// Done when the criterion is met, or after its round of speeds in condition.
	isDone { |coverage, elapsedS, condition| ^coverage.isMet or: { elapsedS >= this.exploreSFor(condition) } }

	// The answer to question after a condition, from stats (an Event: meanSpeedMmPerS in the
	// area, maxForceN, coverage fraction, friction and audio on or off; after a threshold condition
	// trials and correct, the number of trials and of right answers).
	answer { |question, stats|
		var lo, hi, level;
		if(stats[\trials].notNil) { ^this.prAnswerAfterTrials(question, stats) };
		^switch(question.kind,
			\text, {
				"simulated: % in the fragment at % mm/s on average, friction up to % N, % % covered".format(
					if(stats[\friction]) { "felt friction" } { "no friction" },
					stats[\meanSpeedMmPerS].round(0.1), stats[\maxForceN].round(0.001),
					(stats[\coverage] * 100).round(1), "%")
			},
			\rating, {
				// How strongly it was held: the friction met, from the paper's low to its high force.
				lo = question.options[0];
				hi = question.options[1];
				level = (stats[\maxForceN] - FrictionPilot.paperLoForceN)
					/ (FrictionPilot.paperHiForceN - FrictionPilot.paperLoForceN);
				(lo + (level.clip(0, 1) * (hi - lo))).round.asInteger
			},
			\choice, { Routine { thisThread.randSeed = seed + question.key.hash; question.options.choose.yield }.next }
		)
	}

	// After a threshold condition: its share of right answers, as text or on a rating's scale.
	prAnswerAfterTrials { |question, stats|
		var share = stats[\correct] / max(1, stats[\trials]);
		^switch(question.kind,
			\text, { "simulated: % of % trials answered right by its model observer".format(stats[\correct],
				stats[\trials]) },
			\rating, { (question.options[0] + (share * (question.options[1] - question.options[0]))).round.asInteger },
			\choice, { Routine { thisThread.randSeed = seed + question.key.hash; question.options.choose.yield }.next }
		)
	}

	asEvent { ^(seed: seed, exploreS: exploreS) ++ settings }

	printOn { |stream| stream << this.class.name << "(" << seed << ")" }

	prInit {
		if(seed.isInteger.not) {
			Error("FrictionStudySimParticipant: seed must be an Integer, got %".format(seed)).throw
		};
		if(exploreS.notNil and: { exploreS.isNumber.not or: { exploreS <= 0 } or: { exploreS == inf } }) {
			Error("FrictionStudySimParticipant: exploreS must be a finite number > 0, got %".format(exploreS)).throw
		};
		// A person: how hard a fingertip pushes, how firmly it holds a speed, how fast it adapts to
		// the surface, and the speeds it calls slow and fast (the paper's device: 2.6 to 334 mm/s).
		settings = Routine {
			thisThread.randSeed = seed;
			(maxPushN: rrand(1.5, 2.2), gainNSPerM: rrand(6.0, 12.0), adaptS: rrand(2.0, 4.0),
				slowMmPerS: rrand(5.0, 8.0), fastMmPerS: rrand(220.0, 300.0), tiers: 6,
				// Its thresholds: a friction-level difference (N, over 0.3 N), how late the sound may
				// come (ms), a grating period difference (mm, over 2 mm).
				thresholds: (force: exprand(0.03, 0.09), asynchrony: exprand(10.0, 40.0), grating: exprand(0.2, 0.6))
			).yield
		}.next;
	}
}
