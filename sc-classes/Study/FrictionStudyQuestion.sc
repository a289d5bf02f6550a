// A question asked after a condition of a FrictionStudy: free text, a rating on a scale of whole
// numbers, or a forced choice among options. It checks an answer and turns it into the text that
// answers.csv holds.
FrictionStudyQuestion {
	var <key, <text, <kind, <options;

	// Free text (spoken descriptions typed by the experimenter, or typed by the participant).
	*text { |key, text| ^this.newCopyArgs(key, text, \text, []).prCheck }

	// A whole number from lo to hi; loLabel and hiLabel name the scale's ends.
	*rating { |key, text, lo = 1, hi = 7, loLabel = "", hiLabel = ""|
		^this.newCopyArgs(key, text, \rating, [lo, hi, loLabel, hiLabel]).prCheck
	}

	// One of options (Strings).
	*choice { |key, text, options| ^this.newCopyArgs(key, text, \choice, options).prCheck }

	// answer as the text written to answers.csv, or an Error naming what is wrong with it.
	check { |answer|
		^switch(kind,
			\text, {
				if(answer.isString.not) { Error("%: the answer must be a String, got %".format(key, answer)).throw };
				answer
			},
			\rating, {
				if(answer.isInteger.not or: { answer < options[0] } or: { answer > options[1] }) {
					Error("%: the rating must be a whole number from % to %, got %".format(
						key, options[0], options[1], answer)).throw
				};
				answer.asString
			},
			\choice, {
				if(options.includesEqual(answer).not) {
					Error("%: the answer must be one of %, got %".format(key, options, answer)).throw
				};
				answer
			}
		)
	}

	asEvent { ^(key: key, text: text, kind: kind, options: options) }

	printOn { |stream| stream << this.class.name << "(" << key.cs << ", " << kind.cs << ")" }

	prCheck {
		var where = "FrictionStudyQuestion." ++ kind;
		if(key.isKindOf(Symbol).not) { Error("%: key must be a Symbol, got %".format(where, key)).throw };
		if(text.isString.not or: { text.isEmpty }) {
			Error("%: text must be a non-empty String, got %".format(where, text)).throw
		};
		if(kind == \rating and: {
			options[0].isInteger.not or: { options[1].isInteger.not } or: { options[0] >= options[1] }
		}) {
			Error("%: lo and hi must be whole numbers with lo < hi, got % and %".format(where, options[0],
				options[1])).throw
		};
		if(kind == \choice and: {
			options.isSequenceableCollection.not or: { options.size < 2 } or: { options.any { |o| o.isString.not } }
		}) {
			Error("%: options must be two or more Strings, got %".format(where, options)).throw
		};
	}
}
