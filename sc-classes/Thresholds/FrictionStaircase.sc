// Levitt's transformed up-down staircase (JASA 49, 1971): one wrong answer raises the level,
// `down` right answers in a row lower it. It converges on the level answered right with
// probability 0.5 ^ (1 / down): 70.7 % for 1-up-2-down, 79.4 % for 1-up-3-down. The step
// rule: stepSizes[i] is the step after i reversals (the last one stays), added (\lin) or, in
// log10 units, multiplied (\log: level * 10 ^ step). It ends after `reversals` reversals or
// maxTrials trials; the estimate is the mean of the levels at the last `estimateReversals`
// reversals (their geometric mean for \log).
FrictionStaircase : FrictionProcedure {
	var <start, <down, <stepSizes, <stepType, <reversals, <maxTrials, <minLevel, <maxLevel, <estimateReversals;
	var nextLevel, <trials, <reversalLevels, direction, rightInRow = 0;

	*new { |start = 1, down = 2, stepSizes = #[0.2, 0.1, 0.05], stepType = \log, reversals = 12,
		maxTrials = 100, minLevel, maxLevel, estimateReversals = 8|
		^super.new.prInit(start, down, stepSizes, stepType, reversals, maxTrials, minLevel, maxLevel,
			estimateReversals)
	}

	// Levitt's two rules by name.
	*oneUpTwoDown { |start = 1, stepSizes = #[0.2, 0.1, 0.05], stepType = \log, reversals = 12, maxTrials = 100|
		^this.new(start, 2, stepSizes, stepType, reversals, maxTrials)
	}
	*oneUpThreeDown { |start = 1, stepSizes = #[0.2, 0.1, 0.05], stepType = \log, reversals = 12, maxTrials = 100|
		^this.new(start, 3, stepSizes, stepType, reversals, maxTrials)
	}

	prInit { |argStart, argDown, argStepSizes, argStepType, argReversals, argMaxTrials, argMin, argMax, argEstimate|
		var where = "FrictionStaircase";
		if(#[\lin, \log].includes(argStepType).not) {
			Error("%: stepType must be \\lin or \\log, got %".format(where, argStepType)).throw
		};
		stepType = argStepType;
		start = FrictionCheck.finite(argStart, "start", where);
		if(stepType == \log) { FrictionPsychometric.checkLevel(start, where) };
		if(argDown.isInteger.not or: { argDown < 1 }) {
			Error("%: down must be an Integer >= 1, got %".format(where, argDown)).throw
		};
		down = argDown;
		if(argStepSizes.isSequenceableCollection.not or: { argStepSizes.isEmpty } or: {
			argStepSizes.every { |s| s.isNumber and: { s > 0 } and: { s.abs != inf } }.not
		}) {
			Error("%: stepSizes must be a non-empty Array of numbers > 0, got %".format(where, argStepSizes)).throw
		};
		stepSizes = argStepSizes.asArray;
		[argReversals, argMaxTrials, argEstimate].do { |n, i|
			if(n.isInteger.not or: { n < 1 }) {
				Error("%: % must be an Integer >= 1, got %".format(where,
					#[reversals, maxTrials, estimateReversals][i], n)).throw
			}
		};
		reversals = argReversals;
		maxTrials = argMaxTrials;
		estimateReversals = argEstimate;
		minLevel = argMin ?? { if(stepType == \log) { 0 } { -inf } };
		maxLevel = argMax ? inf;
		nextLevel = start.clip(minLevel, maxLevel);
		trials = [];
		reversalLevels = [];
	}

	// The level where the rule converges: p(correct) = 0.5 ^ (1 / down).
	targetProbability { ^0.5 ** down.reciprocal }

	isFinished { ^reversalLevels.size >= reversals or: { trials.size >= maxTrials } }
	// The lowest and highest level it can ask for (inf when unbounded).
	levelRange { ^[minLevel, maxLevel] }

	// The level of the next trial (also after the last one).
	level { ^nextLevel }

	next { ^if(this.isFinished) { nil } { nextLevel } }

	respond { |level, correct|
		var move;
		FrictionCheck.boolean(correct, "correct", "FrictionStaircase.respond");
		trials = trials.add((level: level, correct: correct));
		if(correct) {
			rightInRow = rightInRow + 1;
			if(rightInRow >= down) { rightInRow = 0; move = -1 }
		} {
			rightInRow = 0;
			move = 1
		};
		move !? {
			if(direction.notNil and: { move != direction }) { reversalLevels = reversalLevels.add(level) };
			direction = move;
			nextLevel = this.prStep(level, move).clip(minLevel, maxLevel)
		}
	}

	prStep { |from, move|
		var step = stepSizes.clipAt(reversalLevels.size);
		^if(stepType == \log) { from * (10 ** (step * move)) } { from + (step * move) }
	}

	// (threshold:, sd:, reversals:): the mean (geometric for \log) of the last estimateReversals
	// reversal levels and their sd (in log10 units for \log); nil threshold before any trial.
	estimate {
		var used = reversalLevels.keep(estimateReversals.neg), values, mean;
		if(used.isEmpty) { used = trials.collect(_.level).keep(-1) };
		if(used.isEmpty) { ^(threshold: nil, sd: nil, reversals: 0) };
		values = if(stepType == \log) { used.log10 } { used };
		mean = values.mean;
		^(threshold: if(stepType == \log) { 10 ** mean } { mean },
			sd: if(values.size > 1) { (values - mean).squared.sum / (values.size - 1) } { 0 }.sqrt,
			reversals: used.size)
	}

	asEvent {
		^(kind: \staircase, start: start, down: down, stepSizes: stepSizes, stepType: stepType,
			reversals: reversals, maxTrials: maxTrials, minLevel: minLevel, maxLevel: maxLevel,
			estimateReversals: estimateReversals, targetProbability: this.targetProbability)
	}
}
