// The puck's buttons from a device slot: [left, right, middle], each 1 while down, else 0. A button
// down in any report of a block reads 1 for that block, so a click shorter than a block is kept.
FrictionButtons : MultiOutUGen {
	*kr { |device = 0| ^this.multiNew('control', device) }
	*ar { |device = 0| ^this.multiNew('audio', device) }

	init { |... theInputs|
		inputs = theInputs;
		^this.initOutputs(3, rate)
	}

	checkInputs {
		var device = inputs[0];
		if(device.isNumber and: { device.isInteger.not and: { device.frac != 0 } or: { device < 0 } }) {
			^"device must be a slot index (an Integer >= 0), got %".format(device)
		};
		^this.checkValidInputs
	}
}
