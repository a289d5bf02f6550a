// The Weibull's parameters on a grid (every threshold x slope x lapse, guess fixed) with a log
// posterior over them: QUEST+ updates it trial by trial, the constant stimuli fit it by maximum
// likelihood. Grid points run threshold-major, then slope, then lapse (python3-questplus's order,
// so that ties break alike). The log posterior is kept in double; a flat prior.
FrictionPsychometricGrid {
	var <thresholds, <slopes, <lapses, <guess;
	// Per grid point: its threshold, slope and lapse (Arrays of the grid's size).
	var <thresholdOf, <slopeOf, <lapseOf;
	var <logPosterior, probabilitiesAt, logSignalsAt, logsAt;

	*new { |thresholds, slopes, lapses, guess = 0.5|
		^super.new.prInit(thresholds, slopes, lapses, guess)
	}

	prInit { |argThresholds, argSlopes, argLapses, argGuess|
		var where = "FrictionPsychometricGrid";
		thresholds = this.prCheckAxis(argThresholds, "thresholds", where, { |v| v > 0 });
		slopes = this.prCheckAxis(argSlopes, "slopes", where, { |v| v > 0 });
		lapses = this.prCheckAxis(argLapses, "lapses", where, { |v| v >= 0 and: { v < 0.5 } });
		guess = FrictionCheck.finite(argGuess, "guess", where);
		if(guess < 0 or: { guess >= 1 }) { Error("%: guess must be in [0, 1), got %".format(where, guess)).throw };
		thresholdOf = Array.new(this.size);
		slopeOf = Array.new(this.size);
		lapseOf = Array.new(this.size);
		thresholds.do { |t| slopes.do { |b| lapses.do { |l|
			thresholdOf.add(t); slopeOf.add(b); lapseOf.add(l)
		} } };
		probabilitiesAt = Dictionary.new;
		logSignalsAt = Dictionary.new;
		logsAt = Dictionary.new;
		this.reset
	}

	prCheckAxis { |values, name, where, valid|
		if(values.isSequenceableCollection.not or: { values.isEmpty } or: {
			values.every { |v| v.isNumber and: { v.isNaN.not and: { v.abs != inf and: { valid.(v) } } } }.not
		}) {
			Error("%: % must be a non-empty Array of valid numbers, got %".format(where, name, values)).throw
		};
		^values.collect(_.asFloat)
	}

	size { ^thresholds.size * slopes.size * lapses.size }

	// A flat prior.
	reset { logPosterior = Array.fill(this.size, this.size.reciprocal.log) }

	// p(correct) at level for every grid point (an Array of Floats), kept for the levels asked
	// for again (QUEST+'s and the constant stimuli's few levels).
	probabilities { |level|
		^probabilitiesAt[level] ?? {
			var p = FrictionPsychometric.weibull(level, thresholdOf, slopeOf, guess, lapseOf);
			probabilitiesAt[level] = p;
			p
		}
	}

	// Bayes' rule for one trial: log p(answer | level, parameters) added to each grid point, then
	// normalised (the log posterior's exp sums to 1). In place, in inlined loops: a trial allocates
	// nothing. (Array arithmetic made about 10 arrays of the grid's size a trial; SuperCollider
	// 3.13's collector, run that often after a long session, now and then broke on its own heap in
	// the QUEST+ example: ARCHITECTURE.md, sclang 3.13's stack, caught errors and its collector.)
	update { |level, correct|
		var logs = this.prLogsAt(level)[if(correct) { 0 } { 1 }];
		var n = logPosterior.size, k = 0, v, top = -inf, sum = 0.0;
		while { k < n } {
			v = logPosterior[k] + logs[k];
			logPosterior[k] = v;
			if(v > top) { top = v };
			k = k + 1
		};
		k = 0;
		while { k < n } { sum = sum + (logPosterior[k] - top).exp; k = k + 1 };
		top = top + sum.log;
		k = 0;
		while { k < n } { logPosterior[k] = logPosterior[k] - top; k = k + 1 };
	}

	// [log p, log(1 - p)] at level for every grid point (Arrays of Floats), kept per level.
	prLogsAt { |level|
		^logsAt[level] ?? {
			var p = this.probabilities(level);
			var logs = [this.prLogOf(p), this.prLogOf(1 - p)];
			logsAt[level] = logs;
			logs
		}
	}

	// log of probabilities, 0 taken as 1e-300: an answer a grid point calls impossible (a lapse of
	// 0 far above its threshold) makes it all but impossible, and 0 trials of it count 0, not nan.
	prLogOf { |p| ^p.max(1e-300).log }

	// The posterior (an Array summing to 1).
	posterior { ^logPosterior.exp }

	// The log-likelihood of counts: correct[i] of total[i] trials right at levels[i], for every grid
	// point (a Signal: float sums, made of primitive calls; a few ulp of a log-likelihood do not
	// move its maximum). The grid's own posterior is not used.
	logLikelihoodOf { |levels, correct, total|
		var sum = Signal.newClear(this.size);
		levels.do { |level, i|
			var logs = this.prLogSignalsAt(level);
			sum = sum + (logs[0] * correct[i]) + (logs[1] * (total[i] - correct[i]))
		};
		^sum
	}

	// prLogsAt's as Signals, kept per level.
	prLogSignalsAt { |level|
		^logSignalsAt[level] ?? {
			var logs = this.prLogsAt(level).collect { |values| Signal.newFrom(values) };
			logSignalsAt[level] = logs;
			logs
		}
	}

	// An Event of the parameters: \mean (posterior means, and the threshold's posterior sd) or
	// \mode (the grid point of the highest posterior).
	estimate { |by = \mean|
		var w = this.posterior, thresholdMean;
		if(by == \mode) { ^this.pointAt(w.maxIndex) };
		thresholdMean = (w * thresholdOf).sum;
		^(threshold: thresholdMean, slope: (w * slopeOf).sum, lapse: (w * lapseOf).sum,
			sd: (w * (thresholdOf - thresholdMean).squared).sum.sqrt, guess: guess)
	}

	// The parameters of grid point i (an Event).
	pointAt { |i| ^(threshold: thresholdOf[i], slope: slopeOf[i], lapse: lapseOf[i], guess: guess) }

	asEvent { ^(thresholds: thresholds, slopes: slopes, lapses: lapses, guess: guess) }
}
