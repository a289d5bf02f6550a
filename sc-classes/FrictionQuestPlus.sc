// QUEST+ (Watson, Journal of Vision 17(3):10, 2017) for the Weibull of FrictionPsychometric: a
// posterior over a grid of thresholds, slopes and lapse rates (FrictionPsychometricGrid, flat
// prior), and each next level the one of `levels` whose answer is expected to leave the least
// entropy in it. As Debian's python3-questplus with stim_selection_method 'min_entropy' and
// param_estimation_method 'mean' (the bench and tests/scenes/test_threshold_procedures.py give
// both the same answers and compare).
FrictionQuestPlus {
	var <levels, <grid, <maxTrials, <trials;
	// Per level (as Signals over the grid): p(correct), and p log p + (1 - p) log(1 - p).
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
		correctOf = levels.collect { |l| Signal.newFrom(grid.probabilities(l)) };
		negEntropyOf = levels.collect { |l|
			var p = grid.probabilities(l);
			// 0 log 0 = 0: a grid point certain of the answer adds no entropy.
			Signal.newFrom((p * p.max(1e-300).log) + ((1 - p) * (1 - p).max(1e-300).log))
		};
		trials = [];
	}

	isFinished { ^trials.size >= maxTrials }

	// The expected entropy after a trial at levels[i] is, up to a constant of all levels,
	// -H(p) + sum posterior * (-H(p per grid point)), where p = sum posterior * p(correct): the
	// two outcomes' entropies written out, their posterior log terms cancel. Signals (float)
	// make the sums primitive calls; the posterior itself stays double.
	next {
		var posterior, expected;
		if(this.isFinished) { ^nil };
		posterior = Signal.newFrom(grid.posterior);
		expected = correctOf.collect { |correct, i|
			var p = (posterior * correct).integral.clip(1e-12, 1 - 1e-12);
			(p * p.log) + ((1 - p) * (1 - p).log) - (posterior * negEntropyOf[i]).integral
		};
		^levels[expected.minIndex]
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
