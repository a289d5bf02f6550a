// A model observer: answers forced-choice trials from a known psychometric function (the Weibull
// of FrictionPsychometric) with its own seeded random numbers, so that a procedure, an experiment
// or a whole study runs with no one at the device and its threshold estimate can be checked
// against the threshold the observer was given.
FrictionObserver {
	var <threshold, <slope, <lapse, <guess, <seed, rng;

	// threshold: the level (> 0) at which p(correct) = guess + (1 - guess - lapse) (1 - 1/e);
	// slope: the Weibull's exponent (> 0); lapse: the rate of wrong answers however large the
	// level, in [0, 0.5); guess: 1/2 for two intervals; seed: nil draws one (kept in asEvent).
	*new { |threshold = 1, slope = 3.5, lapse = 0.02, guess = 0.5, seed|
		^super.new.prInit(threshold, slope, lapse, guess, seed)
	}

	prInit { |argThreshold, argSlope, argLapse, argGuess, argSeed|
		var where = "FrictionObserver";
		threshold = FrictionPsychometric.checkLevel(argThreshold, where);
		slope = FrictionCheck.finite(argSlope, "slope", where);
		lapse = FrictionCheck.finite(argLapse, "lapse", where);
		guess = FrictionCheck.finite(argGuess, "guess", where);
		if(slope <= 0) { Error("%: slope must be > 0, got %".format(where, slope)).throw };
		if(lapse < 0 or: { lapse >= 0.5 }) { Error("%: lapse must be in [0, 0.5), got %".format(where, lapse)).throw };
		if(guess < 0 or: { guess >= 1 }) { Error("%: guess must be in [0, 1), got %".format(where, guess)).throw };
		seed = argSeed ?? { 2147483647.rand };
		rng = this.class.randomSource(seed)
	}

	// A Routine whose own random numbers, seeded, each call of next draws: rng.next({ 1.0.rand })
	// evaluates the function inside it. The procedures draw from one too.
	*randomSource { |seed|
		^Routine { |function| loop { function = function.value.yield } }.randSeed_(seed)
	}

	// p(correct) at level.
	probability { |level| ^FrictionPsychometric.weibull(level, threshold, slope, guess, lapse) }

	// The level at which p(correct) = p: where a staircase should converge (levelAt(0.707) for
	// 1-up-2-down, levelAt(0.794) for 1-up-3-down).
	levelAt { |p| ^FrictionPsychometric.levelAt(p, threshold, slope, guess, lapse) }

	// One trial at level: true (correct) with probability p(level), drawn from the observer's own
	// random numbers.
	answer { |level|
		FrictionPsychometric.checkLevel(level, "FrictionObserver.answer");
		^rng.next({ 1.0.rand }) < this.probability(level)
	}

	// Draws what n trials' answers would (their answers unused): an observer that answered n trials
	// before a crash goes on, once skipped, as it would have without the crash.
	skip { |n| n.do { rng.next({ 1.0.rand }) } }

	// Runs procedure to its end, this observer answering every trial; onTrial.(procedure, n) after
	// the n-th (e.g. to take its estimate as the trials go). Returns procedure.estimate. With no
	// device: what a procedure does with a known observer (how many trials it needs, its bias).
	runProcedure { |procedure, onTrial|
		var level;
		while { (level = procedure.next).notNil } {
			procedure.respond(level, this.answer(level));
			onTrial.value(procedure, procedure.trials.size)
		};
		^procedure.estimate
	}

	asEvent { ^(kind: \observer, threshold: threshold, slope: slope, lapse: lapse, guess: guess, seed: seed) }

	printOn { |stream| stream << "FrictionObserver(" <<* [threshold, slope, lapse, guess] << ")" }
}
