// The puck's position (mm) and speed (mm/s) from a device slot, at audio rate:
// [x, y, speedX, speedY]. origin (mm) is subtracted from x in double precision.
FrictionMouseIn : MultiOutUGen {
	*ar { |device = 0, origin = 0, interpolation = 1|
		^this.multiNew('audio', device, origin, interpolation)
	}

	*kr { |device = 0, origin = 0, interpolation = 1|
		^this.multiNew('control', device, origin, interpolation)
	}

	init { |... theInputs|
		inputs = theInputs;
		^this.initOutputs(4, rate)
	}

	checkInputs {
		var device = inputs[0], interpolation = inputs[2];
		if(device.isNumber and: { device.isInteger.not and: { device.frac != 0 } or: { device < 0 } }) {
			^"device must be a slot index (an Integer >= 0), got %".format(device)
		};
		if(interpolation.isNumber and: { [0, 1, 2].includes(interpolation).not }) {
			^"interpolation must be 0 (hold), 1 (linear, the paper) or 2 (predictive), got %".format(interpolation)
		};
		^this.checkValidInputs
	}
}
