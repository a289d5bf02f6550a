// A script for the simulated hand: target positions over time along x or on the surface (x, y),
// speed segments along x, the 2D scripts (a line at an angle, a circle, a raster), a participant who
// explores a strip with a push (explore), or (for tests) a constant push along x. The 2D scripts
// are made into (time, x, y) paths by the server (device/sim/HandScript), at a constant speed from
// t = 0. The simulator pulls the puck towards the target through a spring-damper with a force
// limit, so friction slows it as the paper's subjects reported.
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

	// [[timeS, xMm, yMm], ...]: target positions on the surface, linear in between, held after the last.
	*path2D { |timeXYMm|
		^this.newCopyArgs(3, this.prCheckTuples(timeXYMm, "path2D", "[timeS, xMm, yMm]", 3, true))
	}

	// From (x0, y0) mm for lengthMm at angleDeg (counter-clockwise from +x), at speedMmPerS.
	*line { |angleDeg = 0, lengthMm = 50, speedMmPerS = 50, x0 = 0, y0 = 0|
		^this.newCopyArgs(4, this.prCheckParams([x0, y0, angleDeg, lengthMm, speedMmPerS], "line", 4))
	}

	// turns turns (up to 1000) counter-clockwise around (cx, cy) mm from (cx + radiusMm, cy).
	*circle { |radiusMm = 10, speedMmPerS = 50, turns = 1, cx = 0, cy = 0|
		^this.newCopyArgs(5, this.prCheckParams([cx, cy, radiusMm, speedMmPerS, turns], "circle", 3))
	}

	// rows rows (whole, 1..1000) of widthMm, +x then -x, spread over heightMm along y, from (x0, y0).
	*raster { |widthMm = 20, heightMm = 20, rows = 5, speedMmPerS = 50, x0 = 0, y0 = 0|
		^this.newCopyArgs(6, this.prCheckParams([x0, y0, widthMm, heightMm, rows, speedMmPerS], "raster", 5))
	}

	// A participant exploring the strip [fromMm, toMm] along x (device/sim/ExploringHand): it
	// sweeps it back and forth at intended speeds that step from slowMmPerS to fastMmPerS in tiers
	// geometric steps of tierS s each (then from slow again), pushing with a force (at most maxPushN)
	// made of the resistance it has learnt (time constant adaptS s) and gainNSPerM (N per m/s) per
	// speed shortfall. A push, not a path: it is slowed, and dwells, where friction is high.
	*explore { |fromMm = 0, toMm = 50, slowMmPerS = 10, fastMmPerS = 200, tiers = 4, tierS = 5, maxPushN = 1.5,
		gainNSPerM = 10, adaptS = 0.5|
		var values = [fromMm, toMm, slowMmPerS, fastMmPerS, tiers, tierS, maxPushN, gainNSPerM, adaptS];
		values.do { |v|
			if(v.isNumber.not or: { v.isNaN } or: { v.abs == inf }) {
				Error("FrictionHand.explore: arguments must be finite numbers, got %".format(values)).throw
			}
		};
		if(fromMm >= toMm) {
			Error("FrictionHand.explore: fromMm (%) must be below toMm (%)".format(fromMm, toMm)).throw
		};
		if(slowMmPerS <= 0 or: { fastMmPerS < slowMmPerS }) {
			Error("FrictionHand.explore: speeds must be 0 < slowMmPerS <= fastMmPerS, got % and %".format(
				slowMmPerS, fastMmPerS)).throw
		};
		if(tiers.isInteger.not or: { tiers < 1 } or: { tiers > 100 }) {
			Error("FrictionHand.explore: tiers must be an Integer from 1 to 100, got %".format(tiers)).throw
		};
		[\tierS, tierS, \maxPushN, maxPushN, \gainNSPerM, gainNSPerM, \adaptS, adaptS].pairsDo { |name, v|
			if(v <= 0) { Error("FrictionHand.explore: % must be > 0, got %".format(name, v)).throw }
		};
		^this.newCopyArgs(7, values.collect(_.asFloat))
	}

	// A constant push of forceN along x (tests of the puck's dynamics).
	*force { |forceN|
		^this.newCopyArgs(2, [], FrictionCheck.finite(forceN, "forceN", "FrictionHand.force"))
	}

	// The arguments of the kfOpenSim command: kind, count, values...
	asCommandArgs {
		var values = case { kind == 2 } { [forceN] } { kind >= 4 } { points } { points.flatten(1) };
		^[kind, values.size] ++ values
	}

	// How long the script runs, in s (0 for a constant force; an explorer's one round of its tiers).
	duration {
		var p = points;
		^switch(kind,
			0, { p.last[0] }, 1, { p.sum { |q| q[1] } }, 3, { p.last[0] },
			4, { p[3] / p[4] },
			5, { 2pi * p[2] * p[4] / p[3] },
			6, { (p[2].abs * p[4] + if(p[4] > 1) { p[3].abs } { 0 }) / p[5] },
			7, { p[4] * p[5] },
			{ 0 })
	}

	printOn { |stream|
		var kinds = [\path, \speeds, \force, \path2D, \line, \circle, \raster, \explore];
		stream << this.class.name << "(" << kinds[kind] << ")"
	}

	*prCheckTuples { |tuples, method, shape, size, ascending|
		var last = -inf;
		if(tuples.isSequenceableCollection.not or: { tuples.isEmpty }) {
			Error("FrictionHand.%: expects a non-empty array of % %".format(method, shape,
				if(size == 2) { "pairs" } { "triples" })).throw
		};
		tuples.do { |p|
			var finite = { |v| v.isNumber and: { v.isNaN.not and: { v.abs != inf } } };
			if(p.isSequenceableCollection.not or: { p.size != size } or: { p.every(finite).not }) {
				Error("FrictionHand.%: each entry must be % with finite numbers, got %".format(method, shape, p)).throw
			};
			if(ascending) {
				if(p[0] < last) {
					Error("FrictionHand.%: times must ascend, got % after %".format(method, p[0], last)).throw
				};
				last = p[0];
			};
		};
		^tuples.collect { |p| p.collect(_.asFloat) }
	}

	// The 2D scripts' numbers: finite, a speed > 0; the server checks the rest (counts, bounds).
	*prCheckParams { |values, method, speedIndex|
		values.do { |v|
			if(v.isNumber.not or: { v.isNaN } or: { v.abs == inf }) {
				Error("FrictionHand.%: arguments must be finite numbers, got %".format(method, values)).throw
			}
		};
		if(values[speedIndex] <= 0) { Error("FrictionHand.%: speedMmPerS must be > 0".format(method)).throw };
		^values.collect(_.asFloat)
	}

	*prCheckPairs { |pairs, method, shape, ascending| ^this.prCheckTuples(pairs, method, shape, 2, ascending) }
}
