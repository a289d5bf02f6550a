// The experimenter's window of a FrictionStudySession: who and what runs (participant, condition,
// time, state), the live view of the condition's pilot (FrictionView), the coverage map (the
// fragment's parts against the speed range, FrictionStudyCoverage) with a cue when the criterion
// is met, and the controls: next, repeat, pause, abort. It listens on its own output pair (the
// session copies the participant's audio there).
FrictionStudyExperimenterWindow {
	classvar <coveredColor, <emptyColor, <metColor, <puckColor;
	var <session, <window, <infoText, <cueText, <coverageView, <viewHolder, <liveView;
	var <nextButton, <repeatButton, <pauseButton, <abortButton, task, dirty = false, <frozen = false;

	*initClass {
		// Distinct colours, so that a test finds the cells in a screenshot.
		coveredColor = Color(0.1, 0.55, 0.35);
		emptyColor = Color.gray(0.9);
		metColor = Color(0.6, 0.9, 0.6);
		puckColor = Color(0.86, 0.08, 0.24);
	}

	*new { |session, bounds| ^super.newCopyArgs(session).prInit(bounds) }

	// A new condition runs: its pilot's live view replaces the last one.
	showCondition {
		liveView !? { liveView.free };
		liveView = FrictionView.pilot(session.pilot, viewHolder, viewHolder.bounds.moveTo(0, 0));
		viewHolder.layout.add(liveView.asView);
		liveView.follow = false;
		liveView.rangeMm = session.condition.areaMm + [-10, 10];
		liveView.paused = frozen;
		this.refresh;
	}

	// A monitor frame arrived (the map is redrawn at the window's own rate).
	frame { dirty = true }

	// true: nothing is redrawn (the texts, the map and the live view keep their last picture) until
	// false again, as FrictionView.paused. For Image.fromWindow: it draws the window inside the
	// interpreter, and a view with a redraw pending then calls back into it and sclang hangs.
	frozen_ { |bool|
		frozen = bool == true;
		liveView !? { liveView.paused = frozen };
		if(frozen.not) { this.refresh }
	}

	refresh {
		var s = session, c = s.coverage, met;
		if(window.isNil or: { frozen }) { ^this };
		infoText.string = "participant %    condition % of %: %    %    % s%".format(s.participant, s.position + 1,
			s.conditionCount, s.condition !? { s.condition.name } ? "-", s.state,
			s.elapsedS.round(0.1), s.condition !? { " of " ++ s.condition.maxTimeS } ? "");
		met = c.notNil and: { c.isMet };
		cueText.string = if(c.isNil) { "coverage: -" } {
			"coverage % % (area % %, speeds % %; criterion % %)%".format((c.fraction * 100).round(1), "%",
				(c.areaFraction * 100).round(1), "%", (c.speedFraction * 100).round(1), "%",
				(c.criterion * 100).round(1), "%", if(met) { ": MET" } { "" })
		};
		cueText.background = if(met) { metColor } { Color.gray(0.95) };
		pauseButton.value = s.paused.binaryValue;
		coverageView.refresh;
	}

	close {
		task !? { task.stop };
		liveView !? { liveView.free };
		window !? { window.close };
		window = nil;
	}

	prInit { |bounds|
		var buttonFont = Font.sansSerif(14);
		window = Window("Experimenter: %".format(session.study.name), bounds ?? { Rect(840, 60, 900, 760) });
		infoText = StaticText().font_(Font.sansSerif(15, true));
		cueText = StaticText().font_(Font.sansSerif(14)).minHeight_(28);
		coverageView = UserView().background_(Color.white).minHeight_(200).drawFunc_({ |v| this.prDrawCoverage(v) });
		viewHolder = View().layout_(VLayout().margins_(0)).minHeight_(320);
		nextButton = Button().font_(buttonFont).states_([["next"]]).action_({ session.next });
		repeatButton = Button().font_(buttonFont).states_([["repeat"]]).action_({ session.repeat });
		pauseButton = Button().font_(buttonFont).states_([["pause"], ["go on", Color.white, Color(0.7, 0.45, 0.1)]])
			.action_({ |b| session.pause(b.value == 1) });
		abortButton = Button().font_(buttonFont).states_([["abort", Color.white, Color(0.65, 0.1, 0.1)]])
			.action_({ session.abort });
		window.layout = VLayout(infoText, [viewHolder, stretch: 3], cueText, [coverageView, stretch: 2],
			HLayout(nextButton, repeatButton, pauseButton, abortButton)).margins_(8).spacing_(6);
		window.onClose = { task !? { task.stop }; window = nil };
		window.front;
		task = Routine { loop { if(window.notNil) { this.refresh }; dirty = false; 0.1.wait } }.play(AppClock);
	}

	// The map: position along x (the fragment's parts), speed up (slow at the bottom, log scale);
	// covered cells filled, the puck's cell outlined.
	prDrawCoverage { |v|
		var c = session.coverage, b = v.bounds, left = 70, bottom = 28, w, h, cw, ch, puck;
		Pen.color = Color.black;
		Pen.stringAtPoint("speed (mm/s)", 4 @ 2, Font.sansSerif(11));
		if(c.isNil) { ^this };
		w = b.width - left - 10;
		h = b.height - bottom - 18;
		cw = w / c.positionBins;
		ch = h / c.speedBins;
		c.positionBins.do { |p|
			c.speedBins.do { |k|
				Pen.color = if(c.cells[p][k]) { coveredColor } { emptyColor };
				Pen.fillRect(Rect(left + (p * cw) + 1, 18 + h - ((k + 1) * ch) + 1, cw - 2, ch - 2));
			}
		};
		Pen.color = Color.black;
		(c.speedBins + 1).do { |k|
			var speed = c.slowMmPerS * ((c.fastMmPerS / c.slowMmPerS) ** (k / c.speedBins));
			Pen.stringAtPoint(speed.round(1).asString, 8 @ (18 + h - (k * ch) - 7), Font.sansSerif(10));
		};
		Pen.stringAtPoint("% mm".format(c.areaMm[0].round(0.1)), left @ (b.height - bottom + 4), Font.sansSerif(10));
		Pen.stringAtPoint("% mm: position in the fragment".format(c.areaMm[1].round(0.1)),
			(left + w - 190) @ (b.height - bottom + 4), Font.sansSerif(10));
		puck = session.monitor !? { |m| c.cellOf(m.positionMm, m.speedMmPerS) };
		puck !? {
			Pen.color = puckColor;
			Pen.width = 3;
			Pen.strokeRect(Rect(left + (puck[0] * cw), 18 + h - ((puck[1] + 1) * ch), cw, ch));
		};
	}
}
