// One condition of a FrictionStudy: a scene (the paper's pilot signal under a mapping, friction
// on or off, audio on or off), the instruction shown to the participant, how it ends (the
// participant's "done", or maxTimeS) and the questions asked after it. Or a threshold condition
// (*threshold): a forced-choice experiment (FrictionThreshold) run on the device, each of its
// trials a row of the session's trials.csv.
FrictionStudyCondition {
	// The scene's settings and their defaults; any other key is refused.
	classvar <sceneDefaults;
	var <name, <scene, <instruction, <questions, <maxTimeS;
	// A threshold condition's: a Function that makes the experiment (a new one for each run: its
	// procedure keeps the trials), how a person answers (\keys, \buttons) and a Function of a seed
	// that makes the model observer answering for a simulated participant.
	var <makeExperiment, <answers, <makeObserver;

	*initClass {
		// mapping: a name of Table 1 or samples per mm; origin: where the fragment begins (mm);
		// amp: the audio's level when audio is on; surfaceMm: how much of the fragment lies on the
		// surface (mapping 3's 3 m do not fit: the paper's participants explored its first part).
		sceneDefaults = (mapping: \mapping1, friction: true, audio: true, origin: 0, amp: 0.5, surfaceMm: 100);
	}

	*new { |name, scene, instruction = "", questions, maxTimeS = 300|
		^super.newCopyArgs(name, scene, instruction, questions ? [], maxTimeS).prCheck
	}

	// A threshold condition: makeExperiment.value gives a new FrictionThreshold for each run (made
	// once here too, so that a Function giving anything else is refused when the study is made).
	// answers: \keys or \buttons for a person; makeObserver.value(seed): the answers of a
	// simulated participant (FrictionObserver); nil: the simulated participant's own observer for
	// the experiment's kind (observerFor).
	*threshold { |name, makeExperiment, instruction = "", questions, maxTimeS = 1800, answers = \keys, makeObserver|
		var c = this.new(name, (mapping: \mapping2, surfaceMm: 40), instruction, questions, maxTimeS), made;
		if(makeExperiment.isFunction.not) {
			Error("FrictionStudyCondition.threshold(%): makeExperiment must be a Function".format(name)).throw
		};
		made = makeExperiment.value;
		if(made.isKindOf(FrictionThreshold).not) {
			Error("FrictionStudyCondition.threshold(%): makeExperiment must give a FrictionThreshold, got %".format(
				name, made)).throw
		};
		if(answers != \keys and: { answers != \buttons }) {
			Error("FrictionStudyCondition.threshold(%): answers must be \\keys or \\buttons, got %".format(name,
				answers)).throw
		};
		^c.prThreshold(makeExperiment, answers, makeObserver)
	}

	isThreshold { ^makeExperiment.notNil }

	prThreshold { |argMake, argAnswers, argObserver|
		makeExperiment = argMake;
		answers = argAnswers;
		makeObserver = argObserver;
	}

	// The scene with every default filled in.
	settings { ^sceneDefaults.copy.putAll(scene) }

	samplesPerMm { ^FrictionCheck.samplesPerMm(this.settings[\mapping], "FrictionStudyCondition") }

	// The part of the fragment on the surface, [fromMm, toMm]: what coverage measures.
	areaMm {
		var s = this.settings;
		^[s[\origin], s[\origin] + min(FrictionPilot.signalFrames / this.samplesPerMm, s[\surfaceMm])]
	}

	// The condition as an Event (a session's manifest): with its area on the surface, so that the
	// report needs nothing but the session folder, and a threshold condition's experiment (one made
	// for it: its procedure's settings), so that a resume can tell a changed one.
	asEvent {
		^(name: name, scene: this.settings, areaMm: this.areaMm, instruction: instruction, maxTimeS: maxTimeS,
			questions: questions.collect(_.asEvent), threshold: this.isThreshold, answers: answers,
			experiment: makeExperiment !? { |make| make.value.asEvent })
	}

	printOn { |stream| stream << this.class.name << "(" << name.cs << ")" }

	prCheck {
		var where = "FrictionStudyCondition(%)".format(name);
		if(name.isKindOf(Symbol).not or: { name.asString.every { |c| c.isAlphaNum or: { "_-".includes(c) } }.not }) {
			Error("FrictionStudyCondition: name must be a Symbol of letters, digits, _ and -, got %".format(
				name.cs)).throw
		};
		if(scene.isKindOf(Dictionary).not) { Error("%: scene must be an Event, got %".format(where, scene)).throw };
		scene.keysDo { |key|
			if(sceneDefaults.includesKey(key).not) {
				Error("%: unknown scene parameter % (known: %)".format(where, key.cs,
					sceneDefaults.keys.asArray.sort.join(", "))).throw
			}
		};
		scene = scene.copy;
		FrictionCheck.samplesPerMm(this.settings[\mapping], where);
		[\friction, \audio].do { |key| FrictionCheck.boolean(this.settings[key], key, where) };
		[\origin, \amp].do { |key| FrictionCheck.finite(this.settings[key], key, where) };
		if(this.settings[\surfaceMm].isNumber.not or: { this.settings[\surfaceMm] <= 0 }) {
			Error("%: surfaceMm must be > 0, got %".format(where, this.settings[\surfaceMm])).throw
		};
		if(instruction.isString.not) {
			Error("%: instruction must be a String, got %".format(where, instruction)).throw
		};
		if(questions.isSequenceableCollection.not or: { questions.any { |q| q.isKindOf(FrictionStudyQuestion).not } }) {
			Error("%: questions must be an Array of FrictionStudyQuestion, got %".format(where, questions)).throw
		};
		if(questions.collect(_.key).asSet.size != questions.size) {
			Error("%: two questions have one key: %".format(where, questions.collect(_.key))).throw
		};
		if(maxTimeS.isNumber.not or: { maxTimeS.isNaN } or: { maxTimeS <= 0 } or: { maxTimeS == inf }) {
			Error("%: maxTimeS must be a finite number > 0 (s), got %".format(where, maxTimeS)).throw
		};
	}
}
