// The psychometric function of the threshold procedures, one form for all of them (the model
// observer, QUEST+, the constant stimuli's fit, python/kfstudy/psychometric.py): a Weibull in
// the stimulus level x > 0 (a difference in N, ms or mm) for a forced choice,
//   p(x) = guess + (1 - guess - lapse) * (1 - exp(-(x / threshold) ^ slope)),
// guess = 1/2 for two intervals. At x = threshold, p = guess + (1 - guess - lapse) * (1 - 1/e):
// 81.6 % for 2AFC without lapses. It is Debian's python3-questplus weibull on its linear scale and
// psignifit's Weibull, so the bench hands the same numbers to both.
FrictionPsychometric {

	// p(correct) at level (a number or an Array of them).
	*weibull { |level, threshold, slope, guess = 0.5, lapse = 0|
		^guess + ((1 - guess - lapse) * (1 - exp(((level / threshold) ** slope).neg)))
	}

	// The level at which p(correct) is p (guess < p < 1 - lapse): the inverse of weibull.
	*levelAt { |p, threshold, slope, guess = 0.5, lapse = 0|
		var fraction = (p - guess) / (1 - guess - lapse);
		if(fraction <= 0 or: { fraction >= 1 }) {
			Error("FrictionPsychometric.levelAt: p must lie between guess % and 1 - lapse %, got %".format(
				guess, 1 - lapse, p)).throw
		};
		^threshold * ((1 - fraction).log.neg ** slope.reciprocal)
	}

	// Checks a level: a finite number > 0 (the Weibull's domain).
	*checkLevel { |level, where|
		FrictionCheck.finite(level, "level", where);
		if(level <= 0) { Error("%: level must be > 0, got %".format(where, level)).throw };
		^level
	}

	// count levels from lo to hi (both > 0), evenly spaced on a log scale.
	*logLevels { |lo, hi, count|
		if(lo <= 0 or: { hi <= lo } or: { count < 2 }) {
			Error("FrictionPsychometric.logLevels: needs 0 < lo < hi and count >= 2, got % % %".format(
				lo, hi, count)).throw
		};
		^Array.fill(count, { |i| lo * ((hi / lo) ** (i / (count - 1))) })
	}
}
