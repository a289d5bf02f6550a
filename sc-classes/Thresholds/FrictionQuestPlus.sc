// QUEST+ (Watson, Journal of Vision 17(3):10, 2017) for the Weibull of FrictionPsychometric: a
// posterior over a grid of thresholds, slopes and lapse rates (FrictionPsychometricGrid, flat
// prior), and each next level the one of `levels` whose answer is expected to leave the least
// entropy in it. As Debian's python3-questplus with stim_selection_method 'min_entropy' and
// param_estimation_method 'mean' (the bench and tests/scenes/test_threshold_procedures.py give
// both the same answers and compare).
FrictionQuestPlus : FrictionProcedure {
	var <levels, <grid, <maxTrials, <trials;
	// Per level (Arrays over the grid): p(correct), and p log p + (1 - p) log(1 - p).
	var correctOf, negEntropyOf;

	// levels: the levels to choose from (> 0); thresholds, slopes, lapses: the grid (nil: 40
	// thresholds over levels' range on a log scale, slopes 1.5..6, lapses 0..0.04).
	*new { |levels, thresholds, slopes, lapses, guess = 0.5, maxTrials = 48|
		^super.new.prInit(levels, thresholds, slopes, lapses, guess, maxTrials)
	}

	prInit { |argLevels, thresholds, slopes, lapses, guess, argMaxTrials|
		var where = "FrictionQuestPlus";
		if(argLevels.isSequenceableCollection.not or: { argLevels.isEmpty }) {
			Error("%: levels must be a non-empty Array, got %".format(where, argLevels)).throw
		};
		argLevels.do { |l| FrictionPsychometric.checkLevel(l, where) };
		if(argMaxTrials.isInteger.not or: { argMaxTrials < 1 }) {
			Error("%: maxTrials must be an Integer >= 1, got %".format(where, argMaxTrials)).throw
		};
		levels = argLevels.asArray.collect(_.asFloat);
		maxTrials = argMaxTrials;
		grid = FrictionPsychometricGrid(
			thresholds ?? { FrictionPsychometric.logLevels(levels.minItem, levels.maxItem, 40) },
			slopes ? #[1.5, 2, 3, 4, 6], lapses ? #[0, 0.02, 0.04], guess);
		correctOf = levels.collect { |l| grid.probabilities(l) };
		negEntropyOf = levels.collect { |l|
			var p = grid.probabilities(l);
			// 0 log 0 = 0: a grid point certain of the answer adds no entropy.
			(p * p.max(1e-300).log) + ((1 - p) * (1 - p).max(1e-300).log)
		};
		trials = [];
	}

	isFinished { ^trials.size >= maxTrials }
	// The lowest and highest level it can ask for.
	levelRange { ^[levels.minItem, levels.maxItem] }

	// The expected entropy after a trial at levels[i] is, up to a constant of all levels,
	// -H(p) + sum posterior * (-H(p per grid point)), where p = sum posterior * p(correct): the
	// two outcomes' entropies written out, their posterior log terms cancel. The sums in double,
	// in inlined loops: a trial allocates only the posterior (FrictionPsychometricGrid.update says
	// why that matters).
	next {
		var posterior, n, i = 0, k, w, p, negEntropy, correct, expected, best, bestIndex;
		if(this.isFinished) { ^nil };
		posterior = grid.posterior;
		n = posterior.size;
		while { i < levels.size } {
			correct = correctOf[i];
			negEntropy = negEntropyOf[i];
			p = 0.0;
			expected = 0.0;
			k = 0;
			while { k < n } {
				w = posterior[k];
				p = p + (w * correct[k]);
				expected = expected - (w * negEntropy[k]);
				k = k + 1
			};
			p = p.clip(1e-12, 1 - 1e-12);
			expected = expected + (p * p.log) + ((1 - p) * (1 - p).log);
			// The first of equal ones, as minIndex.
			if(bestIndex.isNil or: { expected < best }) { best = expected; bestIndex = i };
			i = i + 1
		};
		^levels[bestIndex]
	}

	respond { |level, correct|
		FrictionCheck.boolean(correct, "correct", "FrictionQuestPlus.respond");
		FrictionPsychometric.checkLevel(level, "FrictionQuestPlus.respond");
		grid.update(level, correct);
		trials = trials.add((level: level, correct: correct))
	}

	// (threshold:, slope:, lapse:, sd:, guess:): posterior means and the threshold's posterior sd.
	estimate { ^grid.estimate(\mean) }

	asEvent { ^(kind: \questPlus, levels: levels, maxTrials: maxTrials, grid: grid.asEvent) }
}
