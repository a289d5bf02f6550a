// Friction (N) that steers the movement towards a target speed: loForce up to the target, rising by
// gain N for every mm/s above it, at most hiForce. speedX, speedY: FrictionMouseIn's outputs 2 and 3.
SpeedGovernor : UGen {
	*ar { |speedX = 0, speedY = 0, target = 50, gain = 0.005, loForce = 0.14, hiForce = 1.4|
		^this.multiNew('audio', speedX, speedY, target, gain, loForce, hiForce)
	}

	*kr { |speedX = 0, speedY = 0, target = 50, gain = 0.005, loForce = 0.14, hiForce = 1.4|
		^this.multiNew('control', speedX, speedY, target, gain, loForce, hiForce)
	}

	// Literal values are checked here; values from controls keep the last good one on the server.
	checkInputs {
		var finite = { |v| v.isNumber.not or: { v.isNaN.not and: { v.abs != inf } } };
		[[2, "target"], [3, "gain"]].do { |p|
			var v = inputs[p[0]];
			if(finite.(v).not or: { v.isNumber and: { v < 0 } }) {
				^"% must be a finite number >= 0, got %".format(p[1], v)
			}
		};
		[[4, "loForce"], [5, "hiForce"]].do { |p|
			if(finite.(inputs[p[0]]).not) { ^"% must be finite, got %".format(p[1], inputs[p[0]]) }
		};
		^this.checkValidInputs
	}
}
