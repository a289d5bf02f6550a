// Sends a force (N) to a device slot as 1 ms frames; outputs the force actually commanded.
// All FrictionOut of one slot are combined (the forces above the device's minimum add up), so
// the device gets one frame per millisecond however many write to it.
FrictionOut : UGen {
	*ar { |device = 0, force = 0|
		this.prCheckChannels(device, force);
		^this.multiNew('audio', device, force)
	}

	*kr { |device = 0, force = 0|
		this.prCheckChannels(device, force);
		^this.multiNew('control', device, force)
	}

	// Several channels of force for one device would be summed by the combining rule, which is
	// rarely what a multichannel signal means: refused here, when the SynthDef is built.
	// Several devices, one channel each (FrictionOut.ar([0, 1], [f0, f1])), are fine.
	*prCheckChannels { |device, force|
		var devices, forces = force.asArray;
		if(forces.size <= 1) { ^this };
		devices = device.asArray;
		if(devices.size < forces.size or: { devices.asSet.size < devices.size }) {
			Error("FrictionOut: force has % channels for one device (%); give one force "
				"(e.g. force.sum, or Mix) or one device per channel".format(forces.size, device)).throw
		};
	}

	checkInputs {
		var device = inputs[0];
		if(device.isNumber and: { device.frac != 0 or: { device < 0 } }) {
			^"device must be a slot index (an Integer >= 0), got %".format(device)
		};
		^this.checkValidInputs
	}
}
