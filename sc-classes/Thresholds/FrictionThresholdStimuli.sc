// What a FrictionThreshold trial plays, per experiment: a SynthDef whose \trial trigger starts a
// trial's two intervals, timed on the server (trialControls): \intervalS long each, \gapS after
// each, the first with \level1, the second with \level2 (0 in the reference, the trial's level
// in the target). Between intervals the force requested is 0 N (the device's minimum) and nothing
// is heard. One synth plays a whole run: a FrictionOut that stopped and started for each interval
// would turn the magnet off and on between them. Only what a trial needs: the force, the pilot's
// sound and friction, or a grating, on the device the puck moves on.
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
				SynthDef(name, {
					var active, level;
					#active, level = this.trialControls;
					FrictionOut.ar(index, active * (settings[\baseForceN] + level))
				})
			},
			// (b) the pilot: the sound delayed by the device's audioDelay (with the force) plus the
			// level (ms) in the target: sound that far behind the force.
			\asynchrony, {
				var delayS = if(device.isKindOf(FrictionDevice)) { device.audioDelay } {
					FrictionPilot.paperAudioDelayS };
				SynthDef(name, {
					var active, level, delay, p;
					#active, level = this.trialControls;
					delay = (delayS + (level / 1000)).clip(0, maxAsynchronyS);
					p = FrictionPilot.ar(index, \bufnum.kr(0), settings[\samplesPerMm], 0, active,
						settings[\amp] * active, delay, maxAudioDelay: maxAsynchronyS);
					Out.ar(\out.kr(0), p[\delayedAudio] ! 2)
				})
			},
			// (c) a grating of the reference's period, plus the level (mm) in the target.
			\grating, {
				SynthDef(name, {
					var x = FrictionMouseIn.ar(index)[0], active, level;
					#active, level = this.trialControls;
					FrictionOut.ar(index, active * FrictionPattern.grating(x, settings[\periodMm] + level,
						settings[\duty], 0.1, settings[\loForceN], settings[\hiForceN]))
				})
			}
		)
	}

	// Inside a synth: [active (1 during an interval, 0 between), level (\level1 from the trial's
	// start, \level2 from its second interval's)]. The server times the intervals, so that sclang
	// standing still while a trial plays (a garbage collection, a long evaluation, a loaded machine)
	// changes nothing in them. A \trial while one plays starts the next at once.
	*trialControls {
		var trial = \trial.tr(0), intervalS = \intervalS.kr(1.5), gapS = \gapS.kr(0.5);
		var sinceS = Sweep.kr(trial), started = PulseCount.kr(trial) > 0;
		var second = sinceS >= (intervalS + gapS);
		^[started * ((sinceS < intervalS) + (second * (sinceS < (2 * intervalS + gapS)))),
			Select.kr(second, [\level1.kr(0), \level2.kr(0)])]
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
