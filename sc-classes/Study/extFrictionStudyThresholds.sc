// The three ready-made threshold experiments (FrictionThreshold: a friction-level difference, the
// sound-to-force asynchrony, a grating period difference) as conditions of a study, each a QUEST+
// run over the levels a person at the paper's device could meet. A simulated participant answers
// them through its own model observers (FrictionStudySimParticipant.observerFor), whose known
// thresholds the report sets beside the fits.
+ FrictionStudy {
	// The levels each experiment's QUEST+ chooses from: N added to 0.3 N; ms the sound comes late;
	// mm added to a 2 mm grating period.
	*thresholdLevels {
		^(force: FrictionPsychometric.logLevels(0.005, 0.3, 30),
			asynchrony: FrictionPsychometric.logLevels(1, 200, 30),
			grating: FrictionPsychometric.logLevels(0.02, 2, 30))
	}

	// The three conditions: trials of two intervals (intervalS each, gapS after each), answered on
	// the keys or the puck's buttons (answers: \keys or \buttons).
	*thresholdConditions { |trials = 40, answers = \keys, intervalS = 1.5, gapS = 0.5|
		var levels = this.thresholdLevels, how, quest, question;
		if(trials.isInteger.not or: { trials < 1 }) {
			Error("FrictionStudy.thresholdConditions: trials must be an Integer >= 1, got %".format(trials)).throw
		};
		how = if(answers == \buttons) {
			"Press the left button if it was the first interval, the right if the second."
		} { "Press 1 if it was the first interval, 2 if the second." };
		quest = { |kind| FrictionQuestPlus(levels[kind], maxTrials: trials) };
		question = FrictionStudyQuestion.text(\how, "How did you tell the two intervals apart?");
		^[
			FrictionStudyCondition.threshold(\forceStep, {
				FrictionThreshold.force(quest.(\force), 0.3, intervalS, gapS)
			}, "Keep moving the puck back and forth over the surface. Each trial has two intervals; in one of them "
				"the surface holds the puck a little more firmly. " ++ how, [question], answers: answers),
			FrictionStudyCondition.threshold(\asynchrony, {
				FrictionThreshold.asynchrony(quest.(\asynchrony), \mapping2, 0.5, intervalS, gapS)
			}, "Keep moving the puck back and forth over the surface, and listen. Each trial has two intervals; in "
				"one of them the sound comes a little after what you feel. " ++ how, [question], answers: answers),
			FrictionStudyCondition.threshold(\gratingStep, {
				FrictionThreshold.grating(quest.(\grating), 2, intervalS: intervalS, gapS: gapS)
			}, "Keep moving the puck back and forth over the surface. Each trial has two intervals of ridges; in one "
				"of them the ridges lie a little further apart. " ++ how, [question], answers: answers)
		]
	}

	// The three conditions as a study of their own, in a balanced Latin square over participants.
	*thresholds { |trials = 40, answers = \keys, intervalS = 1.5, gapS = 0.5|
		^this.new("KineticFriction thresholds", this.thresholdConditions(trials, answers, intervalS, gapS),
			\latinSquare, "You will compare two short intervals at a time, many times over, and say which one "
			"was different.")
	}
}
