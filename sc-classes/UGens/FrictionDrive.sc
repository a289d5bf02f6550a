// The drive signal of a DC-coupled audio output for a device's magnet: the device's one force
// (every FrictionOut of it together) through the safety path and the drive calibration
// (FrictionDevice.loadDrive), sample by sample, one server block late. Send it to the
// interface's channel with Out.ar. One per device: a second FrictionDrive of it outputs 0.
FrictionDrive : UGen {
	*ar { |device = 0| ^this.multiNew('audio', device) }

	checkInputs {
		var device = inputs[0];
		if(device.isNumber and: { device.frac != 0 or: { device < 0 } }) {
			^"device must be a slot index (an Integer >= 0), got %".format(device)
		};
		^this.checkValidInputs
	}
}
