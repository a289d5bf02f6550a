// Sends a force (N) to a device slot as 1 ms frames; outputs the force actually commanded.
// All FrictionOut of one slot are combined (the forces above the device's minimum add up, each
// weighted by its fade), so the device gets one frame per millisecond however many write to it.
// fade (0..1): the weight of this force above the minimum. nil: the synth's gate envelope (the
// EnvGen on the \gate control that frees the synth: JITLib's fades, .release, a note's ADSR), so
// the force crossfades as the sound does; 1 when the synth has none.
FrictionOut : UGen {
	var followsGate = false;

	*ar { |device = 0, force = 0, fade|
		this.prCheckChannels(device, force);
		^this.prFollowGate(this.multiNew('audio', device, force, fade ? 1), fade)
	}

	*kr { |device = 0, force = 0, fade|
		this.prCheckChannels(device, force);
		^this.prFollowGate(this.multiNew('control', device, force, fade ? 1), fade)
	}

	*prFollowGate { |ugens, fade|
		if(fade.isNil) { ugens.asArray.do { |ugen| ugen.prFollowsGate = true } };
		^ugens
	}

	prFollowsGate_ { |bool| followsGate = bool }

	// SynthDef.finishBuild calls this once the whole graph is built: the gate envelope that
	// ProxySynthDef (EnvGate) or Function.play (GraphBuilder.makeFadeEnv) adds after the user's
	// function exists by now. Its topological sort reads the inputs again afterwards.
	optimizeGraph {
		var envelope;
		if(followsGate.not) { ^this };
		envelope = this.class.prGateEnvelopeOf(synthDef);
		if(envelope.notNil) { inputs[2] = envelope };
	}

	// The envelope that releases a synth: an EnvGen whose gate is the control named gate and
	// whose doneAction is 2 (it frees the synth). The last built when there are several (in a
	// NodeProxy, the proxy's own fade). nil when there is none.
	*prGateEnvelopeOf { |def|
		var found;
		def.children.do { |ugen|
			if(ugen.isKindOf(EnvGen) and: { ugen.inputs[4] == 2 }
				and: { this.prControlName(def, ugen.inputs[0]) == \gate }) {
				found = ugen
			}
		};
		^found
	}

	// The name of the control an input reads directly, or nil. A Control's outputs are the
	// synth's controls from its specialIndex on (one per value); ControlName.index is the first
	// of a control's values in that same numbering.
	*prControlName { |def, input|
		var index, name;
		if(input.isKindOf(OutputProxy).not or: { input.source.isKindOf(Control).not }) { ^nil };
		index = input.source.specialIndex + input.outputIndex;
		def.allControlNames.do { |cn|
			var size = cn.defaultValue.asArray.size.max(1);
			if(cn.index.notNil and: { index >= cn.index } and: { index < (cn.index + size) }) { name = cn.name }
		};
		^name
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
