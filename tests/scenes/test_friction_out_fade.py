"""FrictionOut's fade input as SynthDefs build it (issue 41): with fade nil it is the synth's gate
envelope, the EnvGen on the control named gate with doneAction 2, whichever way the SynthDef is
built (a plain SynthDef, Function.play's GraphBuilder, JITLib's ProxySynthDef); the given fade
when there is one; 1 when the synth has no such envelope. sclang only, no server."""
from kfharness import sclang

CASES = r"""
var fadeOf = { |def|
    var fo = def.children.detect { |u| u.isKindOf(FrictionOut) }, fade = fo.inputs[2];
    case
    { fade.isNumber } { fade }
    { fade.isKindOf(EnvGen) } { "EnvGen." ++ fade.rate }
    { fade.class.name }
};
var show = { |name, def| "KF-FADE % %".format(name, fadeOf.(def)).postln };
show.(\plain, SynthDef(\a, { FrictionOut.ar(0, DC.ar(0.5)) }));
show.(\adsr, SynthDef(\b, { |gate = 1| FrictionOut.ar(0, DC.ar(0.5)); EnvGen.kr(Env.adsr, gate, doneAction: 2) }));
show.(\given, SynthDef(\c, { |gate = 1| FrictionOut.ar(0, DC.ar(0.5), 0.3); EnvGen.kr(Env.adsr, gate, doneAction: 2) }));
show.(\keeps, SynthDef(\d, { |gate = 1| FrictionOut.ar(0, DC.ar(0.5)); EnvGen.kr(Env.adsr, gate, doneAction: 0) }));
show.(\other, SynthDef(\e, { |level = #[1, 2], gate = 1|
    FrictionOut.ar(0, DC.ar(0.5));
    EnvGen.kr(Env.adsr, level[1], doneAction: 2);  // not the gate
    EnvGen.ar(Env.asr, gate, doneAction: 2)
}));
show.(\functionPlay, GraphBuilder.wrapOut(\f, { FrictionOut.ar(0, DC.ar(0.5)); Silent.ar }, nil, nil, \Out, 0.02));
show.(\functionPlayOut, GraphBuilder.wrapOut(\g, { Out.ar(0, FrictionOut.ar(0, DC.ar(0.5))) }, nil, nil, \Out, 0.02));
show.(\ndefAudio, ProxySynthDef(\h, { FrictionOut.ar(0, DC.ar(0.5)) }));
show.(\ndefControl, ProxySynthDef(\i, { FrictionOut.kr(0, 0.5) }));
show.(\ndefOwnGate, ProxySynthDef(\j, { |gate = 1| FrictionOut.ar(0, DC.ar(0.5)) * EnvGen.kr(Env.asr, gate, doneAction: 2) }));
"""

EXPECTED = {
    "plain": "1",
    "adsr": "EnvGen.control",
    "given": "0.3",
    "keeps": "1",  # an envelope that does not free the synth is not its gate envelope
    "other": "EnvGen.audio",
    "functionPlay": "EnvGen.control",  # makeFadeEnv: the 20 ms fade
    "functionPlayOut": "1",  # returns Out (scalar): Function.play adds no fade envelope
    "ndefAudio": "EnvGen.control",  # EnvGate
    "ndefControl": "EnvGen.control",
    "ndefOwnGate": "EnvGen.control",  # the proxy's own gate envelope (no EnvGate added)
}


def test_fade_is_the_synths_gate_envelope_when_not_given():
    out = sclang.run_script(CASES, name="friction-out-fade")
    found = {words[1]: words[2] for words in (line.split() for line in out.splitlines()) if words[:1] == ["KF-FADE"]}
    assert found == EXPECTED
