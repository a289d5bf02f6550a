// Sends a force (N) to a device slot as 1 ms frames; outputs the force actually commanded.
FrictionOut : UGen {
	*ar { |device = 0, force = 0|
		^this.multiNew('audio', device, force)
	}

	*kr { |device = 0, force = 0|
		^this.multiNew('control', device, force)
	}

	checkInputs {
		var device = inputs[0];
		if(device.isNumber and: { device.frac != 0 or: { device < 0 } }) {
			^"device must be a slot index (an Integer >= 0), got %".format(device)
		};
		^this.checkValidInputs
	}
}
