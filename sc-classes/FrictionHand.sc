// A script for the simulated hand along x: target positions over time, speed segments, or
// (for tests) a constant push. The simulator pulls the puck towards the target through a
// spring-damper with a force limit, so friction slows it as the paper's subjects reported.
FrictionHand {
	var <kind, <points, <forceN;

	// [[timeS, xMm], ...]: target positions, linear in between, held after the last.
	*path { |timeAndPositionMm|
		^this.newCopyArgs(0, this.prCheckPairs(timeAndPositionMm, "path", "[timeS, xMm]", true))
	}

	// [[speedMmPerS, durationS], ...]: target speed segments along x from x = 0.
	*speeds { |speedAndDuration|
		var pairs = this.prCheckPairs(speedAndDuration, "speeds", "[speedMmPerS, durationS]", false);
		pairs.do { |p|
			if(p[1] < 0) { Error("FrictionHand.speeds: durations must be >= 0, got %".format(p[1])).throw }
		};
		^this.newCopyArgs(1, pairs)
	}

	// A constant push of forceN along x (tests of the puck's dynamics).
	*force { |forceN|
		^this.newCopyArgs(2, [], FrictionCheck.finite(forceN, "forceN", "FrictionHand.force"))
	}

	// The arguments of the kfOpenSim command: kind, count, values...
	asCommandArgs {
		var values = if(kind == 2) { [forceN] } { points.flatten(1) };
		^[kind, values.size] ++ values
	}

	// How long the script runs, in s (0 for a constant force).
	duration {
		^switch(kind, 0, { points.last[0] }, 1, { points.sum { |p| p[1] } }, { 0 })
	}

	printOn { |stream| stream << this.class.name << "(" << [\path, \speeds, \force][kind] << ")" }

	*prCheckPairs { |pairs, method, shape, ascending|
		var last = -inf;
		if(pairs.isSequenceableCollection.not or: { pairs.isEmpty }) {
			Error("FrictionHand.%: expects a non-empty array of % pairs".format(method, shape)).throw
		};
		pairs.do { |p|
			var finite = { |v| v.isNumber and: { v.isNaN.not and: { v.abs != inf } } };
			if(p.isSequenceableCollection.not or: { p.size != 2 } or: { p.every(finite).not }) {
				Error("FrictionHand.%: each entry must be % with finite numbers, got %".format(method, shape, p)).throw
			};
			if(ascending) {
				if(p[0] < last) {
					Error("FrictionHand.%: times must ascend, got % after %".format(method, p[0], last)).throw
				};
				last = p[0];
			};
		};
		^pairs.collect { |p| p.collect(_.asFloat) }
	}
}
