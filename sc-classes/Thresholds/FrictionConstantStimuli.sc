// The method of constant stimuli: every level `repeats` times, in a seeded random order; the
// estimate is the maximum-likelihood Weibull (FrictionPsychometric) over a grid of thresholds,
// slopes and lapse rates (FrictionPsychometricGrid), fitted to the counts per level.
FrictionConstantStimuli : FrictionProcedure {
	var <levels, <repeats, <seed, <grid, <order, <trials;

	// levels: the stimulus levels (> 0); grid: a FrictionPsychometricGrid to fit on (nil: 80
	// thresholds spread on a log scale from levels.minItem / 2 to levels.maxItem * 2, slopes
	// 1..8, lapses 0..0.05).
	*new { |levels, repeats = 20, seed, grid|
		^super.new.prInit(levels, repeats, seed, grid)
	}

	// The grid fitted when none is given: 80 thresholds from half the lowest level to twice the
	// highest (log scale), slopes 1 to 8, lapse rates 0 to 0.05. Its p(correct) per level is worked
	// out once per grid: runs that share one (simulations) pass it as grid.
	*defaultGrid { |levels|
		^FrictionPsychometricGrid(FrictionPsychometric.logLevels(levels.minItem / 2, levels.maxItem * 2, 80),
			#[1, 1.5, 2, 2.5, 3, 3.5, 4, 5, 6, 8], #[0, 0.01, 0.02, 0.03, 0.04, 0.05])
	}

	prInit { |argLevels, argRepeats, argSeed, argGrid|
		var where = "FrictionConstantStimuli";
		if(argLevels.isSequenceableCollection.not or: { argLevels.isEmpty }) {
			Error("%: levels must be a non-empty Array, got %".format(where, argLevels)).throw
		};
		argLevels.do { |l| FrictionPsychometric.checkLevel(l, where) };
		if(argRepeats.isInteger.not or: { argRepeats < 1 }) {
			Error("%: repeats must be an Integer >= 1, got %".format(where, argRepeats)).throw
		};
		levels = argLevels.asArray;
		repeats = argRepeats;
		seed = argSeed ?? { 2147483647.rand };
		grid = argGrid ?? { this.class.defaultGrid(levels) };
		order = FrictionObserver.randomSource(seed).next({ (levels ! repeats).flatten.scramble });
		trials = [];
	}

	isFinished { ^trials.size >= order.size }
	// The lowest and highest level it asks for.
	levelRange { ^[levels.minItem, levels.maxItem] }

	next { ^order[trials.size] }

	respond { |level, correct|
		FrictionCheck.boolean(correct, "correct", "FrictionConstantStimuli.respond");
		trials = trials.add((level: level, correct: correct))
	}

	// Right answers and trials per level given, in levels' order: [levels, right, total].
	counts {
		var given = levels.select { |l| trials.any { |t| t.level == l } };
		^[given, given.collect { |l| trials.count { |t| t.level == l and: { t.correct } } },
			given.collect { |l| trials.count { |t| t.level == l } }]
	}

	// (threshold:, slope:, lapse:, guess:): the grid point of the highest likelihood.
	estimate {
		var counts = this.counts, logLikelihood;
		if(trials.isEmpty) { ^(threshold: nil) };
		logLikelihood = grid.logLikelihoodOf(*counts);
		^grid.pointAt(logLikelihood.maxIndex)
	}

	asEvent { ^(kind: \constantStimuli, levels: levels, repeats: repeats, seed: seed, grid: grid.asEvent) }
}
