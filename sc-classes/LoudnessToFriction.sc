// The paper's equations (1) and (2): the mean |in| over the latest window (s), in dB against ref,
// clipped to [loDb, hiDb] and mapped linearly onto [loForce, hiForce] (N).
LoudnessToFriction : UGen {
	*ar { |in, window = 0.001, loDb = -30, hiDb = 0, loForce = 0.14, hiForce = 0.5, ref = 1, maxWindow = 0.05|
		^this.multiNew('audio', in, window, loDb, hiDb, loForce, hiForce, ref, maxWindow)
	}

	*kr { |in, window = 0.001, loDb = -30, hiDb = 0, loForce = 0.14, hiForce = 0.5, ref = 1, maxWindow = 0.05|
		^this.multiNew('control', in, window, loDb, hiDb, loForce, hiForce, ref, maxWindow)
	}

	checkInputs {
		var window = inputs[1], ref = inputs[6], maxWindow = inputs[7];
		if(inputs[0].isNil) { ^"in is required" };
		if(rate == 'audio' and: { inputs[0].rate != 'audio' }) {
			^"in must be audio rate for LoudnessToFriction.ar (got %)".format(inputs[0].rate)
		};
		if(maxWindow.isNumber.not) {
			^"maxWindow is fixed at init and must be a number (s), got %".format(maxWindow)
		};
		if(maxWindow <= 0) { ^"maxWindow must be > 0 s, got %".format(maxWindow) };
		if(window.isNumber and: { window <= 0 or: { window > maxWindow } }) {
			^"window must be > 0 and <= maxWindow (% s), got %".format(maxWindow, window)
		};
		if(ref.isNumber and: { ref <= 0 }) { ^"ref must be > 0, got %".format(ref) };
		^this.checkValidInputs
	}
}
