// What a FrictionThreshold interval plays, per experiment: a SynthDef whose \level control is 0 in
// the reference interval and the trial's level in the target's, and \active 1 during an interval,
// 0 between them (the force requested 0 N: the device's minimum; no sound). One synth plays a
// whole run: a FrictionOut that stopped and started for each interval would turn the magnet off
// and on between them. Only what a trial needs: the force, the pilot's sound and friction, or a
// grating, on the device the puck moves on.
FrictionThresholdStimuli {
	// The longest asynchrony (s) the asynchrony experiment's delay line holds.
	classvar <maxAsynchronyS = 0.25;

	*kinds { ^#[\force, \asynchrony, \grating] }

	*synthDef { |kind, device, settings|
		var index = FrictionCheck.deviceIndex(device, "FrictionThresholdStimuli.synthDef");
		var name = "kfThreshold_%_%".format(kind, index).asSymbol;
		^switch(kind,
			// (a) the reference's force, and the level (N) added in the target.
			\force, {
				SynthDef(name, { FrictionOut.ar(index, \active.kr(0) * (settings[\baseForceN] + \level.kr(0))) })
			},
			// (b) the pilot: the sound delayed by the device's audioDelay (with the force) plus the
			// level (ms) in the target: sound that far behind the force.
			\asynchrony, {
				var delayS = if(device.isKindOf(FrictionDevice)) { device.audioDelay } {
					FrictionPilot.paperAudioDelayS };
				SynthDef(name, {
					var active = \active.kr(0), delay = (delayS + (\level.kr(0) / 1000)).clip(0, maxAsynchronyS);
					var p = FrictionPilot.ar(index, \bufnum.kr(0), settings[\samplesPerMm], 0, active,
						settings[\amp] * active, delay, maxAudioDelay: maxAsynchronyS);
					Out.ar(\out.kr(0), p[\delayedAudio] ! 2)
				})
			},
			// (c) a grating of the reference's period, plus the level (mm) in the target.
			\grating, {
				SynthDef(name, {
					var x = FrictionMouseIn.ar(index)[0];
					FrictionOut.ar(index, \active.kr(0) * FrictionPattern.grating(x, settings[\periodMm] + \level.kr(0),
						settings[\duty], 0.1, settings[\loForceN], settings[\hiForceN]))
				})
			}
		)
	}

	// Inside a synth: sends /kfThresholdButton 1 when the puck's left button goes down, 2 for its
	// right button (FrictionButtons).
	*buttonsReply { |device|
		var buttons = FrictionButtons.kr(FrictionCheck.deviceIndex(device, "FrictionThresholdStimuli.buttonsReply"));
		SendReply.kr(buttons[0], '/kfThresholdButton', 1);
		SendReply.kr(buttons[1], '/kfThresholdButton', 2);
		^buttons
	}
}
