// Plays a 2D surface laid out on the table: a matrix stored row after row in a mono buffer of
// `width` samples per row, read at column (x - originX) * samplesPerMmX and row
// (y - originY) * samplesPerMmY, silent outside the matrix. Positions in mm.
SpatialBufRd2D : UGen {
	*ar { |bufnum = 0, x = 0, y = 0, width = 1, samplesPerMmX = 1, samplesPerMmY, originX = 0, originY = 0,
		interpolation = 4|
		^this.multiNew('audio', bufnum, x, y, width, samplesPerMmX, samplesPerMmY ? samplesPerMmX, originX, originY,
			interpolation)
	}

	*kr { |bufnum = 0, x = 0, y = 0, width = 1, samplesPerMmX = 1, samplesPerMmY, originX = 0, originY = 0,
		interpolation = 4|
		^this.multiNew('control', bufnum, x, y, width, samplesPerMmX, samplesPerMmY ? samplesPerMmX, originX,
			originY, interpolation)
	}

	// Literal values are checked here; values from controls reach the server unchecked, where a bad
	// one keeps the last good one with a message (help: Bad inputs).
	checkInputs {
		var finite = { |v| v.isNumber.not or: { v.isNaN.not and: { v.abs != inf } } };
		var positive = { |v| v.isNumber.not or: { finite.(v) and: { v > 0 } } };
		var width = inputs[3];
		if(rate == 'audio' and: { inputs[1].rate != 'audio' or: { inputs[2].rate != 'audio' } }) {
			^"x and y must be audio rate for SpatialBufRd2D.ar (got %, %); use K2A.ar or SpatialBufRd2D.kr".format(
				inputs[1].rate, inputs[2].rate)
		};
		if(inputs[8].isNumber and: { [1, 2, 4].includes(inputs[8]).not }) {
			^"interpolation must be 1 (none), 2 (linear) or 4 (cubic), got %".format(inputs[8])
		};
		if(width.isNumber and: { finite.(width).not or: { width < 1 } or: { width.frac != 0 } }) {
			^"width must be a whole number of samples per row >= 1, got %".format(width)
		};
		[4, 5].do { |i, k|
			if(positive.(inputs[i]).not) {
				^"samplesPerMm% must be a finite number > 0, got %".format(["X", "Y"][k], inputs[i])
			}
		};
		[6, 7].do { |i, k|
			if(finite.(inputs[i]).not) { ^"origin% must be finite, got %".format(["X", "Y"][k], inputs[i]) }
		};
		^this.checkValidInputs
	}
}
