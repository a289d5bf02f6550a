// The paper's pilot (section 4) as a ready study: the three mappings of Table 1, each first with
// friction off, then on, in that fixed order; free exploration from quite slow to fast until the
// participant is done; the audio sensations described after the audio-only version, the touch
// sensations and how sound and touch relate after the audio-haptic one. The words are section
// 4.1's, addressed to the participant. thresholds: conditions run after the pilot's six (nil: none;
// e.g. FrictionStudy.thresholdConditions, which the paper's pilot did not have).
+ FrictionStudy {
	*pilot { |maxTimeS = 600, thresholds|
		var intro, explore, audio, touch, relate;
		intro = "You will be exploring a number of simple patterns, spread out sideways over the surface. "
		"These patterns are represented in both sound and touch. Move the device while touching it only "
		"with the tips of the middle three fingers of your hand of choice. For each pattern, explore the "
		"surface using speeds from quite slow to fast.";
		explore = "The pattern begins on the surface at the initial position of the device and extends to the "
		"right of it. Explore the surface using speeds from quite slow to fast. ";
		audio = FrictionStudyQuestion.text(\audio, "Please characterize the audio sensations generated.");
		touch = FrictionStudyQuestion.text(\touch, "Please characterize the touch sensations generated.");
		relate = FrictionStudyQuestion.text(\relation,
			"How did you feel that sound and touch did or did not relate to each other?");
		^this.new("KineticFriction pilot (de Jong 2010, section 4)", [\mapping1, \mapping2, \mapping3].collect { |m|
			[
				FrictionStudyCondition((m ++ "-off").asSymbol, (mapping: m, friction: false),
					explore ++ "Afterwards you will describe the audio sensations. Say when you are done exploring.",
					[audio], maxTimeS),
				FrictionStudyCondition((m ++ "-on").asSymbol, (mapping: m, friction: true),
					explore ++ "Afterwards you will describe the touch sensations, and how sound and touch did or did "
					"not relate to each other. Say when you are done exploring.", [touch, relate], maxTimeS)
			]
		}.flatten(1) ++ (thresholds ? []), \fixed, intro)
	}
}
