// The order of a study's conditions for each participant: fixed (as listed, the paper's), a
// balanced Latin square over participants (each condition precedes and follows every other
// equally often: Williams' design; an odd count takes the square and its mirror, 2n rows), or
// a random permutation from a seed stored with the session.
FrictionStudyOrder {
	*kinds { ^#[\fixed, \latinSquare, \random] }

	// The rows of the balanced Latin square of n conditions (indices from 0).
	*latinSquare { |n|
		var first = Array.fill(n, { |i| if(i.odd) { (i + 1) div: 2 } { (n - (i div: 2)) % n } });
		var rows = Array.fill(n, { |r| first.collect { |c| (c + r) % n } });
		^if(n.odd) { rows ++ rows.collect(_.reverse) } { rows }
	}

	// The order (indices from 0) of n conditions for the participant numbered participantIndex
	// (0, 1, ...) under kind, with seed for \random.
	*of { |kind, n, participantIndex = 0, seed = 0|
		^switch(kind,
			\fixed, { (0 .. n - 1) },
			\latinSquare, { var rows = this.latinSquare(n); rows[participantIndex % rows.size] },
			// In a Routine of its own, so that the seed leaves the caller's random numbers alone.
			\random, { Routine { thisThread.randSeed = seed; (0 .. n - 1).scramble.yield }.next },
			{ Error("FrictionStudyOrder: order must be one of %, got %".format(this.kinds, kind.cs)).throw }
		)
	}
}
