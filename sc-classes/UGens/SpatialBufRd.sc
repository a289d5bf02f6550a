// Plays a buffer laid out on the surface: the sample at index (position - origin) * samplesPerMm,
// silent outside the signal. Positions in mm. keep 1: a change of samplesPerMm or origin keeps
// the sample under the puck in place (zoom about the puck), decided on the server.
SpatialBufRd : MultiOutUGen {
	*ar { |numChannels = 1, bufnum = 0, position = 0, samplesPerMm = 1, origin = 0, interpolation = 4, keep = 0|
		^this.multiNew('audio', numChannels, bufnum, position, samplesPerMm, origin, interpolation, keep)
	}

	*kr { |numChannels = 1, bufnum = 0, position = 0, samplesPerMm = 1, origin = 0, interpolation = 4, keep = 0|
		^this.multiNew('control', numChannels, bufnum, position, samplesPerMm, origin, interpolation, keep)
	}

	init { |argNumChannels ... theInputs|
		if(argNumChannels.isKindOf(Integer).not or: { argNumChannels < 1 }) {
			Error("SpatialBufRd: numChannels must be an Integer of at least 1, got %".format(argNumChannels)).throw
		};
		inputs = theInputs;
		^this.initOutputs(argNumChannels, rate)
	}

	argNamesInputsOffset { ^2 }

	// Literal values are checked here; values from controls reach the server unchecked, where a bad
	// samplesPerMm or origin keeps the last good one with a message (help: Bad inputs).
	checkInputs {
		var interpolation = inputs[4], samplesPerMm = inputs[2], origin = inputs[3];
		if(rate == 'audio' and: { inputs[1].rate != 'audio' }) {
			^"position must be audio rate for SpatialBufRd.ar (got %); use K2A.ar or SpatialBufRd.kr".format(
				inputs[1].rate)
		};
		if(interpolation.isNumber and: { [1, 2, 4].includes(interpolation).not }) {
			^"interpolation must be 1 (none), 2 (linear) or 4 (cubic), got %".format(interpolation)
		};
		if(samplesPerMm.isNumber and: { samplesPerMm.isNaN or: { samplesPerMm == inf } or: { samplesPerMm <= 0 } }) {
			^"samplesPerMm must be a finite number > 0, got %".format(samplesPerMm)
		};
		if(origin.isNumber and: { origin.isNaN or: { origin.abs == inf } }) {
			^"origin must be finite, got %".format(origin)
		};
		^this.checkValidInputs
	}
}
