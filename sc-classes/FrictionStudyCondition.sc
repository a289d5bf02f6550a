// One condition of a FrictionStudy: a scene (the paper's pilot signal under a mapping, friction
// on or off, audio on or off), the instruction shown to the participant, how it ends (the
// participant's "done", or maxTimeS) and the questions asked after it.
FrictionStudyCondition {
	// The scene's settings and their defaults; any other key is refused.
	classvar <sceneDefaults;
	var <name, <scene, <instruction, <questions, <maxTimeS;

	*initClass {
		// mapping: a name of Table 1 or samples per mm; origin: where the fragment begins (mm);
		// amp: the audio's level when audio is on; surfaceMm: how much of the fragment lies on the
		// surface (mapping 3's 3 m do not fit: the paper's participants explored its first part).
		sceneDefaults = (mapping: \mapping1, friction: true, audio: true, origin: 0, amp: 0.5, surfaceMm: 100);
	}

	*new { |name, scene, instruction = "", questions, maxTimeS = 300|
		^super.newCopyArgs(name, scene, instruction, questions ? [], maxTimeS).prCheck
	}

	// The scene with every default filled in.
	settings { ^sceneDefaults.copy.putAll(scene) }

	samplesPerMm { ^FrictionCheck.samplesPerMm(this.settings[\mapping], "FrictionStudyCondition") }

	// The part of the fragment on the surface, [fromMm, toMm]: what coverage measures.
	areaMm {
		var s = this.settings;
		^[s[\origin], s[\origin] + min(FrictionPilot.signalFrames / this.samplesPerMm, s[\surfaceMm])]
	}

	asEvent {
		^(name: name, scene: this.settings, instruction: instruction, maxTimeS: maxTimeS,
			questions: questions.collect(_.asEvent))
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
		if(maxTimeS.isNumber.not or: { maxTimeS <= 0 } or: { maxTimeS == inf }) {
			Error("%: maxTimeS must be a finite number > 0 (s), got %".format(where, maxTimeS)).throw
		};
	}
}
