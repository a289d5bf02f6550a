// The participant's window of a FrictionStudySession: the instruction or the question, the answer
// and the done control; nothing else (no time, no coverage, no condition name: what could steer
// the participant is the experimenter's). Space or Return is "done" too while exploring.
FrictionStudyParticipantWindow {
	var <session, <window, <textView, <doneButton, <answerButton, <textAnswer, <choiceRow, <choiceButtons;
	var <mode = \none;
	var <chosen;

	*new { |session, bounds| ^super.newCopyArgs(session).prInit(bounds) }

	// Shows text (an instruction) with the done button, labelled button.
	showInstruction { |text, button = "I am done exploring"|
		mode = \explore;
		textView.string = text;
		doneButton.states = [[button, Color.white, Color(0.15, 0.45, 0.25)]];
		this.prShowAnswer(nil);
		doneButton.visible = true;
	}

	// Shows question (a FrictionStudyQuestion) and the controls to answer it.
	ask { |question|
		var o = question.options;
		mode = \question;
		textView.string = question.text ++ if(question.kind == \rating and: { o[2..3].any(_.notEmpty) }) {
			"\n\n% = %,  % = %".format(o[0], o[2], o[1], o[3])
		} { "" };
		doneButton.visible = false;
		this.prShowAnswer(question);
	}

	showEnd {
		mode = \end;
		textView.string = "Thank you. The session is over.";
		doneButton.visible = false;
		this.prShowAnswer(nil);
	}

	// ---- driven from code, as a participant would (tests) ----

	pressDone { doneButton.valueAction = 0 }
	pressKey { |char = $ | window.view.keyDownAction.value(window.view, char, 0, char.ascii, char.ascii) }
	type { |text| textAnswer.string = text }
	choose { |index| choiceButtons[index].valueAction = 1 }
	submit { answerButton.valueAction = 0 }

	close { window !? { window.close }; window = nil }
	front { window.front }

	prInit { |bounds|
		var font = Font.sansSerif(22), buttonFont = Font.sansSerif(18);
		window = Window("Participant", bounds ?? { Rect(60, 60, 760, 480) }).background_(Color.white);
		textView = StaticText().font_(font).align_(\topLeft).minHeight_(160);
		doneButton = Button().font_(buttonFont).states_([["I am done exploring", Color.white, Color(0.15, 0.45, 0.25)]])
			.minHeight_(48).action_({ if(mode == \explore) { session.done(\window) } });
		textAnswer = TextView().font_(Font.sansSerif(16)).visible_(false);
		choiceButtons = [];
		answerButton = Button().font_(buttonFont).states_([["Answer", Color.white, Color(0.15, 0.3, 0.6)]])
			.minHeight_(40).visible_(false).action_({ this.prSubmit });
		choiceRow = View().layout_(HLayout().margins_(0).spacing_(8));
		window.layout = VLayout([textView, stretch: 1], [textAnswer, stretch: 2], choiceRow, doneButton, answerButton)
			.margins_(24).spacing_(12);
		window.view.keyDownAction = { |view, char|
			if(mode == \explore and: { char == $  or: { char == $\r } }) { session.done(\key); true } { nil }
		};
		window.onClose = { window = nil };
		window.front;
	}

	// The answer controls of question (nil: none): a text field, a row of rating or choice buttons.
	prShowAnswer { |question|
		var values;
		choiceButtons.do(_.remove);
		choiceButtons = [];
		chosen = nil;
		textAnswer.visible = question.notNil and: { question.kind == \text };
		textAnswer.string = "";
		answerButton.visible = question.notNil;
		if(question.isNil or: { question.kind == \text }) { ^this };
		values = if(question.kind == \rating) { (question.options[0] .. question.options[1]) } { question.options };
		choiceButtons = values.collect { |v, i|
			Button().font_(Font.sansSerif(16)).states_([[v.asString], [v.asString, Color.white, Color(0.15, 0.3, 0.6)]])
				.minHeight_(40).action_({ |b| this.prChoose(i, v) })
		};
		choiceButtons.do { |b| choiceRow.layout.add(b) };
	}

	prChoose { |index, value|
		choiceButtons.do { |b, i| b.value = (i == index).binaryValue };
		chosen = value;
	}

	prSubmit {
		var value = if(textAnswer.visible) { textAnswer.string } { chosen };
		if(value.isNil) { ^this };
		try { session.answer(value) } { |error| textView.string = textView.string ++ "\n\n" ++ error.errorString };
	}
}
