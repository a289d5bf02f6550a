"""A device's figures as numbers: the plugin's /kfStatus reply (FrictionDevice.statusValues),
posted by sclang as one `<TAG> <slot> name=value ...` line and read back here. Shared by the
bench and the soak."""

# sclang: defines ~kfPostStatus.(device, tag), to call inside a Routine after the devices ran.
# A statement: it goes after the code's `var` declarations.
SC_POST = r"""
~kfPostStatus = { |dev, tag|
	dev.statusValues({ |v|
		// fault is a Symbol or nil (FrictionDevice.faultOf): 1 for a fault, 0 for none.
		var number = { |x| case { x.isKindOf(Boolean) } { x.binaryValue } { x.isNumber } { x.asFloat }
			{ x.isNil } { 0 } { 1 } };
		"% % %".format(tag, dev.index,
			FrictionDevice.statusFields.collect { |k| "%=%".format(k, number.(v[k])) }.join(" ")).postln
	});
	dev.server.sync;
};
"""


def parse(output, tag):
    """{slot: {field: value}} from the lines `<tag> <slot> name=value ...` (the last of each slot)."""
    out = {}
    for line in output.splitlines():
        if line.startswith(tag + " "):
            words = line.split()
            out[int(words[1])] = {k: float(v) for k, v in (w.split("=", 1) for w in words[2:])}
    return out
