// The argument checks several classes share. Each takes `where`, the class and method the user
// called ("FrictionView.origin_"), and begins its error with it: the message names the call that
// was wrong, not the class that happens to hold the check. Each returns the value it accepted.
FrictionCheck {

	// A finite number (not nan, not inf).
	*finite { |value, name, where|
		if(value.isNumber.not or: { value.isNaN } or: { value.abs == inf }) {
			Error("%: % must be a finite number, got %".format(where, name, value)).throw
		};
		^value
	}

	// true or false (nothing that merely converts to one).
	*boolean { |value, name, where|
		if(value != true and: { value != false }) {
			Error("%: % must be true or false, got %".format(where, name, value)).throw
		};
		^value
	}

	// A FrictionDevice or a slot index; returns the slot index.
	*deviceIndex { |device, where|
		^case
		{ device.isKindOf(FrictionDevice) } { device.index }
		{ device.isInteger and: { device >= 0 } } { device }
		{
			Error("%: device must be a FrictionDevice or a slot index (Integer >= 0), got %".format(
				where, device)).throw
		}
	}

	// A mapping: a name of Table 1 (FrictionPilot.mappings) or a positive finite number of samples
	// per mm; returns samples per mm (a Float).
	*samplesPerMm { |mapping, where|
		var mappings = FrictionPilot.mappings;
		case
		{ mapping.isKindOf(Symbol) or: { mapping.isString } } {
			^mappings[mapping.asSymbol] ?? {
				Error("%: unknown mapping %; use one of % or a number of samples per mm".format(where,
					mapping.asSymbol.cs, mappings.keys.asArray.sort.collect(_.cs).join(", "))).throw
			}
		}
		{ mapping.isNumber } {
			if(mapping.isNaN or: { mapping.abs == inf } or: { mapping <= 0 }) {
				Error("%: samplesPerMm must be a positive finite number, got %".format(where, mapping)).throw
			};
			^mapping.asFloat
		}
		{
			Error("%: mapping must be a Symbol (e.g. \\mapping1) or samples per mm, got %".format(
				where, mapping)).throw
		}
	}

	// A server that is running.
	*serverRunning { |server, where|
		if(server.serverRunning.not) { Error("%: server % is not running".format(where, server)).throw };
		^server
	}
}
