// A live view of one device slot: the buffer's signal laid out on the surface (mm), the puck on
// it, and strip charts of the puck's speed and of the requested and commanded force. Usable as
// its own window or embedded in a layout (like FreqScopeView). This file holds the view's state,
// window and coordinates; extFrictionViewDrawing.sc draws it. Its frames come from a
// FrictionViewMonitor (the server side) and its signal from a FrictionSignalPyramid.
FrictionView {
	classvar <markerColor, <requestedColor, <commandedColor, <speedColor, <signalColor;

	var <device, <server, <pilot, <monitor, buffer, samplesPerMm, origin;
	var <view, <userView, <window, followBox, ownsWindow = false;
	var <follow = false, <zoomToMapping = false, <rangeMm, <>forceRangeN, <minForceN;
	var pyramid, signalBufnum, fetching = false, <isFree = false, refreshPending = false, lastSpm;
	var drag, columnCache, columnKey, <paused = false, <drawn, rangeSet = false;

	*initClass {
		// Distinct colours (drawn without antialiasing) so a test can find them in a screenshot.
		markerColor = Color.new255(220, 20, 60);
		requestedColor = Color.new255(30, 110, 230);
		commandedColor = Color.new255(240, 140, 0);
		speedColor = Color.new255(0, 150, 70);
		signalColor = Color.new255(60, 60, 100);
	}

	// device: a FrictionDevice (its server) or a slot index (Server.default). buffer: the signal
	// laid out from origin (mm) at samplesPerMm. forceBus: a Bus (control or audio) that your synth
	// writes the requested force (N) into, and on a second channel the commanded force (FrictionOut's
	// output). positionBus: a Bus with your synth's position (mm) and optionally speed (mm/s); nil:
	// the view reads FrictionMouseIn on the device itself (counting from when the view opens).
	// parent nil: the view opens its own window.
	*new { |device = 0, buffer, samplesPerMm = 1, origin = 0, forceBus, positionBus, parent, bounds,
		frameRate = 30, historyS = 6|
		var where = "FrictionView.new";
		FrictionViewMonitor.checkSettings(device, forceBus, positionBus, frameRate, historyS, where);
		if(buffer.notNil and: { buffer.isKindOf(Buffer).not }) {
			Error("%: buffer must be a Buffer or nil, got %".format(where, buffer)).throw
		};
		^super.new.prInit(device, buffer, FrictionCheck.samplesPerMm(samplesPerMm, where),
			FrictionCheck.finite(origin, "origin", where), nil, parent, bounds, {
				FrictionViewMonitor(device, forceBus, positionBus, frameRate, historyS)
			})
	}

	// The view of a FrictionPilot: its position, speed and forces as its synth computes them, its
	// buffer and its current mapping (samplesPerMm, origin) followed live.
	*pilot { |pilot, parent, bounds, frameRate = 30, historyS = 6|
		FrictionViewMonitor.checkPilot(pilot, "FrictionView.pilot");
		FrictionViewMonitor.checkSettings(pilot.device, nil, nil, frameRate, historyS, "FrictionView.pilot");
		^super.new.prInit(pilot.device, nil, pilot.samplesPerMm, pilot.origin, pilot, parent, bounds, {
			FrictionViewMonitor.pilot(pilot, frameRate, historyS)
		})
	}

	// ---- the mapping shown ----

	buffer { ^if(pilot.notNil) { pilot.buffer } { buffer } }
	samplesPerMm { ^if(pilot.notNil) { pilot.samplesPerMm } { samplesPerMm } }
	origin { ^if(pilot.notNil) { pilot.origin } { origin } }

	buffer_ { |newBuffer| buffer = newBuffer; this.refreshSignal }
	samplesPerMm_ { |value|
		samplesPerMm = FrictionCheck.samplesPerMm(value, "FrictionView.samplesPerMm_");
		this.refresh
	}
	origin_ { |mm| origin = FrictionCheck.finite(mm, "origin", "FrictionView.origin_"); this.refresh }

	// The signal's first and last sample on the surface (mm).
	fragmentMm {
		var spm = this.samplesPerMm, start = this.origin;
		^[start, start + (max(this.signalFrames - 1, 0) / spm)]
	}

	// The visible part of the surface, [loMm, hiMm].
	rangeMm_ { |loHi|
		if(loHi.size != 2 or: { loHi.any { |v| v.isNumber.not or: { v.isNaN } } } or: { loHi[1] <= loHi[0] }) {
			Error("FrictionView.rangeMm_: expects [loMm, hiMm] with hi > lo, got %".format(loHi)).throw
		};
		rangeMm = loHi.collect(_.asFloat);
		rangeSet = true;
		this.refresh
	}

	// Zoom by factor (< 1 in, > 1 out) about aboutMm (default: the middle of the view).
	zoom { |factor, aboutMm|
		var about = aboutMm ?? { rangeMm.mean };
		factor = factor.clip(1e-3, 1e3);
		rangeMm = about + ((rangeMm - about) * factor);
		rangeSet = true;
		this.refresh
	}

	// Shows the whole fragment (and the puck) with a margin.
	fit {
		var lo, hi, margin, positionMm = this.positionMm;
		if(this.signalFrames > 0) {
			#lo, hi = this.fragmentMm;
			lo = min(lo, positionMm); hi = max(hi, positionMm);
		} {
			lo = positionMm - 10; hi = positionMm + 10;
		};
		margin = max(hi - lo, 1e-3) * 0.08;
		rangeMm = [lo - margin, hi + margin];
		this.refresh
	}

	// true: the view keeps the puck in its middle.
	follow_ { |bool|
		follow = bool == true;
		followBox !? { defer { if(followBox.isClosed.not) { followBox.value = follow } } };
		this.refresh
	}

	// true: when samplesPerMm changes, the view zooms about the puck by the same factor, so the
	// signal keeps its size on screen (as the pilot's re-mapping about the puck does on the surface).
	zoomToMapping_ { |bool| zoomToMapping = bool == true; lastSpm = this.samplesPerMm }

	// ---- the frames (the monitor's) and the signal ----

	forceBus { ^monitor.forceBus }
	positionBus { ^monitor.positionBus }
	frameRate { ^monitor.frameRate }
	historyS { ^monitor.historyS }
	synth { ^monitor.synth }
	positionMm { ^monitor.positionMm }
	speedMmPerS { ^monitor.speedMmPerS }
	forceN { ^monitor.forceN }
	commandedForceN { ^monitor.commandedForceN }
	timeS { ^monitor.timeS }
	frameCount { ^monitor.frameCount }
	historyCount { ^monitor.historyCount }
	// The frames of the strip charts, oldest first: [timeS, positionMm, speedMmPerS, forceN,
	// commandedForceN].
	history { ^monitor.history }

	// The samples of the signal shown (0 until the buffer is fetched).
	signalFrames { ^if(pyramid.notNil) { pyramid.frames } { 0 } }

	// ---- pixels (userView coordinates) ----

	surfaceRect { ^this.prLayout[\surface] }
	speedRect { ^this.prLayout[\speed] }
	forceRect { ^this.prLayout[\force] }

	mmToX { |mm| var r = this.surfaceRect; ^r.left + ((mm - rangeMm[0]) / (rangeMm[1] - rangeMm[0]) * r.width) }
	xToMm { |x| var r = this.surfaceRect; ^rangeMm[0] + ((x - r.left) / r.width * (rangeMm[1] - rangeMm[0])) }
	forceToY { |forceValueN|
		var r = this.forceRect;
		^r.bottom - ((forceValueN - forceRangeN[0]) / (forceRangeN[1] - forceRangeN[0]) * r.height)
	}
	yToForce { |y|
		var r = this.forceRect;
		^forceRangeN[0] + ((r.bottom - y) / r.height * (forceRangeN[1] - forceRangeN[0]))
	}
	// The strip charts' time axis: seconds before the latest frame -> x.
	ageToX { |ageS| var r = this.forceRect; ^r.right - (ageS / this.historyS * r.width) }

	// ---- life cycle ----

	// Fetches the buffer again (after you changed its contents).
	refreshSignal { signalBufnum = nil; this.prFetchSignalIfNeeded(true) }

	refresh {
		if(refreshPending.not and: { isFree.not } and: { paused.not }) {
			refreshPending = true;
			defer {
				refreshPending = false;
				if(isFree.not and: { paused.not } and: { userView.isClosed.not }) { userView.refresh }
			}
		}
	}

	// true: the picture stands still (frames still arrive and fill the history).
	paused_ { |bool| paused = bool == true; this.refresh }

	free {
		if(isFree) { ^this };
		isFree = true;
		monitor.free;
		ServerTree.remove(this, server);
		CmdPeriod.remove(this);
		if(ownsWindow and: { window.notNil } and: { window.isClosed.not }) { defer { window.close } };
		if(ownsWindow.not and: { view.notNil } and: { view.isClosed.not }) { defer { view.remove } };
	}

	close { this.free }

	asView { ^view }
	asLayoutElement { ^view }

	front { window !? { window.front } }

	// A fetch cut off by a quit or Cmd-. is taken again (the monitor starts its synth again itself).
	doOnServerTree { fetching = false }

	// Cmd-. also drops what was deferred or forked: a pending refresh or buffer fetch.
	cmdPeriod { fetching = false; refreshPending = false }

	// Force frames per second the device plays (1000, the paper's; 8000 on a 2.1 board), nil for
	// a slot index (its device unknown here).
	forceRateHz { ^if(device.isKindOf(FrictionDevice)) { (1 / device.specs[\forceFramePeriodS]).round(1e-6) } }

	printOn { |stream| stream << this.class.name << "(" << (pilot ? device) << ")" }

	// ---- private ----

	// Arguments checked by *new and *pilot; makeMonitor: a function that makes the monitor.
	prInit { |argDevice, argBuffer, argSpm, argOrigin, argPilot, parent, bounds, makeMonitor|
		device = argDevice;
		pilot = argPilot;
		server = FrictionDevice.serverOf(device);
		buffer = argBuffer;
		samplesPerMm = argSpm;
		origin = argOrigin;
		minForceN = if(device.isKindOf(FrictionDevice)) { device.specs[\minForceN] } { FrictionPilot.paperLoForceN };
		forceRangeN = case
			{ pilot.notNil } { [0, FrictionPilot.paperHiForceN * 1.2] }
			{ device.isKindOf(FrictionDevice) } { [0, device.specs[\maxForceN]] }
			{ [0, KineticFriction.paperDevice[\maxForceN]] };
		rangeMm = [-10, 10];
		lastSpm = this.samplesPerMm;
		this.prMakeGui(parent, bounds);
		monitor = makeMonitor.value;
		monitor.action = { |m, resumed| this.prFrame(resumed) };
		ServerTree.add(this, server);
		CmdPeriod.add(this);
		if(server.serverRunning.not) {
			"FrictionView: server % is not running; the view starts with it".format(server).warn
		};
		if(pilot.isNil) { this.prFetchSignalIfNeeded(false) };
	}

	prMakeGui { |parent, bounds|
		var fitButton, hint;
		ownsWindow = parent.isNil;
		if(ownsWindow) {
			window = Window("FrictionView: %".format(pilot ? device), bounds ?? { Rect(100, 100, 820, 600) });
			parent = window;
		};
		view = View(parent, if(ownsWindow) { nil } { bounds });
		userView = UserView().background_(Color.white).minSize_(Size(320, 240));
		followBox = CheckBox(text: "follow the puck").value_(follow).action_({ |b| follow = b.value; this.refresh });
		fitButton = Button().states_([["fit"]]).action_({ follow = false; followBox.value = false; this.fit });
		hint = StaticText().string_("wheel: zoom, drag: pan, double-click: fit").stringColor_(Color.gray(0.35));
		view.layout = VLayout(HLayout(followBox, fitButton, [hint, stretch: 1]), [userView, stretch: 1])
			.margins_(4).spacing_(2);
		userView.drawFunc = { this.prDraw };
		userView.mouseWheelAction = { |v, x, y, mod, dx, dy|
			if(dy != 0) { this.zoom(0.8 ** dy.sign, if(follow) { this.positionMm } { this.xToMm(x) }) };
			true
		};
		userView.mouseDownAction = { |v, x, y, mod, button, clickCount|
			if(clickCount == 2) { this.follow_(false); this.fit } { drag = [x, rangeMm.copy] }
		};
		userView.mouseMoveAction = { |v, x, y|
			var r = this.surfaceRect, dmm;
			if(drag.notNil) {
				dmm = (x - drag[0]) / r.width * (drag[1][1] - drag[1][0]);
				if(follow) { this.follow_(false) };
				rangeMm = drag[1] - dmm;
				rangeSet = true;
				this.refresh
			}
		};
		userView.mouseUpAction = { drag = nil };
		view.onClose = { this.free };
		if(ownsWindow) {
			window.layout = VLayout(view).margins_(0);
			window.onClose = { this.free };
			window.front;
		};
	}

	// A frame kept by the monitor (resumed: the first since it was not running).
	prFrame { |resumed|
		var spm, ratio, positionMm = this.positionMm;
		if(isFree) { ^this };
		// The pilot's synth runs only once its buffer is loaded: then fetch it.
		if(pilot.notNil and: { resumed }) { signalBufnum = nil };
		this.prFetchSignalIfNeeded(false);
		spm = this.samplesPerMm;
		if(zoomToMapping and: { spm != lastSpm } and: { lastSpm.notNil }) {
			ratio = lastSpm / spm;
			rangeMm = positionMm + ((rangeMm - positionMm) * ratio);
		};
		lastSpm = spm;
		if(follow) { rangeMm = rangeMm - rangeMm.mean + positionMm };
		this.refresh;
	}

	prFetchSignalIfNeeded { |force|
		var buf = this.buffer;
		if(buf.isNil or: { fetching } or: { isFree } or: { server.serverRunning.not }) { ^this };
		if(force.not and: { signalBufnum == buf.bufnum }) { ^this };
		fetching = true;
		FrictionSignalPyramid.fetch(buf, { |newPyramid, failure|
			fetching = false;
			failure !? { "FrictionView: %".format(failure).warn };
			if(newPyramid.notNil and: { isFree.not }) { this.prSetSignal(newPyramid, buf.bufnum) };
		})
	}

	prSetSignal { |newPyramid, bufnum|
		pyramid = newPyramid;
		signalBufnum = bufnum;
		columnKey = nil;
		// The first signal sets the view, unless the user already chose a range.
		if(rangeSet.not) { this.fit; rangeSet = true } { this.refresh };
	}
}
