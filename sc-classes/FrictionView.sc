// A live view of one device slot: the buffer's signal laid out on the surface (mm), the puck on
// it, and strip charts of the puck's speed and of the requested and commanded force. Usable as
// its own window or embedded in a layout (like FreqScopeView). This class draws; its frames come
// from a FrictionViewMonitor (the server side) and its signal from a FrictionSignalPyramid.
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

	prLayout {
		var b = userView.bounds, w = b.width, h = b.height, left = 64, right = 16, width, avail;
		var surfaceTop = 44, top;
		width = max(w - left - right, 10);
		avail = max(h - surfaceTop - 22 - 20 - 24 - 24, 60);
		top = surfaceTop;
		^(
			header: Rect(4, 2, w - 8, 18),
			surface: Rect(left, top, width, (avail * 0.42).round),
			speed: Rect(left, top + (avail * 0.42).round + 22 + 20, width, (avail * 0.22).round),
			force: Rect(left, top + (avail * 0.64).round + 22 + 20 + 24, width, (avail * 0.36).round)
		)
	}

	prDraw {
		var lay = this.prLayout, font = Font.sansSerif(11), small = Font.sansSerif(9), rows = this.history;
		// What this picture shows (the window may show it a little after it was drawn).
		drawn = (positionMm: this.positionMm, rangeMm: rangeMm.copy, timeS: if(rows.notEmpty) { rows.last[0] },
			surfaceRect: lay[\surface], speedRect: lay[\speed], forceRect: lay[\force],
			forceRangeN: forceRangeN.copy);
		Pen.smoothing = false;
		this.prDrawHeader(lay[\header], font);
		this.prDrawSurface(lay[\surface], small);
		this.prDrawStrip(lay[\speed], small, \speed, rows);
		this.prDrawStrip(lay[\force], small, \force, rows);
	}

	prDrawHeader { |r, font|
		var spm = this.samplesPerMm, forceN = this.forceN, commandedForceN = this.commandedForceN;
		var text = "puck % mm   speed % mm/s".format(this.prFormat(this.positionMm, 2),
			this.prFormat(this.speedMmPerS, 1));
		if(forceN.notNil) { text = text ++ "   force % N requested".format(this.prFormat(forceN, 3)) };
		if(commandedForceN.notNil) { text = text ++ ", % N commanded".format(this.prFormat(commandedForceN, 3)) };
		if(pilot.notNil and: { monitor.running.not }) { text = text ++ "   (the pilot is not playing)" };
		text = text ++ "   % samples/mm, origin % mm".format(this.prFormat(spm, if(spm.frac == 0) { 0 } { 3 }),
			this.prFormat(this.origin, 2));
		Pen.stringInRect(text, r, font, Color.black, \left);
	}

	prDrawSurface { |r, font|
		var spm = this.samplesPerMm, org = this.origin, positionMm = this.positionMm;
		var signalFrames = this.signalFrames, signalPeak = if(pyramid.notNil) { pyramid.peak } { 1 };
		var mid = (r.top + 8 + (r.height / 2)).round, yScale = (r.height - 20) * 0.48 / signalPeak;
		var startMm, endMm, x0, x1, key, px;
		// The mapping of this picture, local: mmToX/xToMm would lay the panels out on every call.
		var mmPerPx = (rangeMm[1] - rangeMm[0]) / r.width;
		var toX = { |mm| r.left + ((mm - rangeMm[0]) / mmPerPx) };
		var toMm = { |x| rangeMm[0] + ((x - r.left) * mmPerPx) };
		Pen.fillColor = Color.gray(0.97); Pen.fillRect(r);
		this.prAxisX(r, rangeMm, font, "position on the surface (mm)");
		Pen.strokeColor = Color.gray(0.85); Pen.width = 1;
		Pen.line(r.left @ mid, r.right @ mid); Pen.stroke;
		if(signalFrames > 0) {
			#startMm, endMm = this.fragmentMm;
			// The signal: min and max of the samples under each pixel column.
			key = [rangeMm, r, spm, org, signalBufnum];
			if(key != columnKey) {
				x0 = toX.(startMm).floor.max(r.left).asInteger;
				x1 = toX.(endMm).ceil.min(r.right - 1).asInteger;
				columnCache = List.new;
				x0.for(x1, { |x|
					var env = pyramid.envelope((toMm.(x) - org) * spm, (toMm.(x + 1) - org) * spm);
					env !? { columnCache.add([x, mid - (env[1] * yScale), mid - (env[0] * yScale)]) };
				});
				columnKey = key;
			};
			Pen.strokeColor = signalColor; Pen.width = 1;
			columnCache.do { |c| Pen.line(c[0] @ c[1], c[0] @ (c[2] + 1)) };
			Pen.stroke;
			// The fragment's ends.
			[startMm, endMm].do { |mm, i|
				var x = toX.(mm).round;
				if(x >= r.left and: { x <= r.right }) {
					var text = if(i == 0) { "start % mm" } { "end % mm" }.format(this.prFormat(mm, 2));
					var at = (if(i == 0) { x + 3 } { x - 3 - (text.size * 5.6) }) @ (r.top + 2);
					Pen.use {
						Pen.strokeColor = Color.gray(0.45); Pen.lineDash = FloatArray[4, 3];
						Pen.line(x @ r.top, x @ r.bottom); Pen.stroke
					};
					Pen.fillColor = Color.gray(0.97); Pen.fillRect(Rect(at.x - 1, at.y, text.size * 5.6 + 2, 13));
					Pen.stringAtPoint(text, at, font, Color.gray(0.2));
				}
			};
		} {
			Pen.stringAtPoint(if(this.buffer.isNil) { "no buffer" } { "fetching the buffer..." },
				(r.left + 8) @ (r.top + 8), font, Color.gray(0.4));
		};
		Pen.strokeColor = Color.gray(0.6); Pen.width = 1; Pen.strokeRect(r);
		// The puck: a bar across the surface and a triangle above it.
		px = toX.(positionMm).round;
		Pen.fillColor = markerColor;
		if(px >= r.left and: { px <= r.right }) {
			Pen.fillRect(Rect(px - 1, r.top + 1, 3, r.height - 1));
			Pen.moveTo((px - 6) @ (r.top - 12)); Pen.lineTo((px + 6) @ (r.top - 12));
			Pen.lineTo(px @ (r.top - 1)); Pen.lineTo((px - 6) @ (r.top - 12));
			Pen.fill;
			Pen.stringAtPoint("puck % mm".format(this.prFormat(positionMm, 2)),
				(if(px > (r.right - 110)) { px - 112 } { px + 9 }) @ (r.top - 16), font, Color.black);
		} {
			Pen.stringAtPoint(if(px < r.left) { "< puck % mm" } { "puck % mm >" }.format(this.prFormat(positionMm, 2)),
				(if(px < r.left) { r.left } { r.right - 110 }) @ (r.top - 16), font, markerColor);
		};
		Pen.stringAtPoint("signal", 4 @ (r.top + 2), font, Color.gray(0.3));
		if(signalFrames > 0) {
			[signalPeak, 0, signalPeak.neg].do { |v|
				var y = mid - (v * yScale);
				Pen.strokeColor = Color.gray(0.6); Pen.line((r.left - 4) @ y, r.left @ y); Pen.stroke;
				Pen.stringInRect(this.prFormat(v, 2), Rect(0, y - 7, r.left - 6, 14), font, Color.gray(0.2), \right);
			}
		};
	}

	prDrawStrip { |r, font, which, rows|
		var historyS = this.historyS, ageToX = { |ageS| r.right - (ageS / historyS * r.width) };
		var latest, range, toY, fragment, labels;
		Pen.fillColor = Color.white; Pen.fillRect(r);
		latest = if(rows.notEmpty) { rows.last[0] } { 0 };
		if(which == \speed) {
			range = this.prSpeedRange(rows);
			labels = [["speed (mm/s)", speedColor], ["puck on the fragment", Color.gray(0.9)]];
		} {
			range = forceRangeN;
			labels = [["force (N)", Color.black], ["requested", requestedColor]]
			++ (if(this.commandedForceN.notNil or: { pilot.notNil }) { [["commanded", commandedColor]] } { [] })
			++ [["min force % N".format(this.prFormat(minForceN, 2)), Color.gray(0.5)]];
		};
		toY = { |v| r.bottom - ((v - range[0]) / (range[1] - range[0]) * r.height).clip(0, r.height) };
		// Grey where the puck was on the fragment.
		if(this.signalFrames > 0) {
			fragment = this.fragmentMm;
			Pen.fillColor = Color.gray(0.9);
			rows.doAdjacentPairs { |a, b|
				if(a[1] >= fragment[0] and: { a[1] <= fragment[1] }) {
					var xa = ageToX.(latest - a[0]), xb = ageToX.(latest - b[0]);
					if(xb > r.left) {
						Pen.fillRect(Rect(xa.max(r.left), r.top + 1, xb - xa.max(r.left) + 1, r.height - 1))
					}
				}
			};
		};
		this.prAxisY(r, range, font);
		this.prAxisX(r, [historyS.neg, 0], font, if(which == \force) { "time (s)" }, true);
		if(which == \force) {
			Pen.use {
				Pen.strokeColor = Color.gray(0.5); Pen.lineDash = FloatArray[2, 3]; Pen.width = 1;
				Pen.line(r.left @ toY.(minForceN), r.right @ toY.(minForceN)); Pen.stroke;
			};
			if(this.forceN.notNil) { this.prTrace(rows, latest, r, toY, 3, requestedColor, 3) };
			if(this.commandedForceN.notNil) { this.prTrace(rows, latest, r, toY, 4, commandedColor, 1) };
		} {
			Pen.strokeColor = Color.gray(0.8);
			Pen.line(r.left @ toY.(0), r.right @ toY.(0)); Pen.stroke;
			this.prTrace(rows, latest, r, toY, 2, speedColor, 2);
		};
		Pen.strokeColor = Color.gray(0.6); Pen.width = 1; Pen.strokeRect(r);
		// Title and legend, above the chart (outside it).
		labels.inject(r.left, { |x, pair, i|
			var text = pair[0], color = pair[1];
			if(i > 0) {
				if(color == Color.gray(0.5)) {
					Pen.use {
						Pen.strokeColor = color; Pen.lineDash = FloatArray[2, 3];
						Pen.line(x @ (r.top - 9), (x + 14) @ (r.top - 9)); Pen.stroke
					};
				} { Pen.fillColor = color; Pen.fillRect(Rect(x, r.top - 12, 14, 6)) };
				x = x + 18;
			};
			Pen.stringAtPoint(text, x @ (r.top - 18), font, Color.black);
			x + (text.size * 6.5) + 14
		});
	}

	prTrace { |rows, latest, r, toY, column, color, width|
		var first = true, historyS = this.historyS, ageToX = { |ageS| r.right - (ageS / historyS * r.width) };
		Pen.strokeColor = color; Pen.width = width;
		rows.do { |row|
			var x = ageToX.(latest - row[0]), point;
			if(x >= r.left) {
				point = x.round @ toY.(row[column]).round;
				if(first) { Pen.moveTo(point); first = false } { Pen.lineTo(point) };
			}
		};
		if(first.not) { Pen.stroke };
		Pen.width = 1;
	}

	// Symmetric, in steps of 1, 2, 5, at least +-10 mm/s.
	prSpeedRange { |rows|
		var peak = rows.inject(10, { |m, row| max(m, row[2].abs) }) * 1.1;
		var step = 10 ** peak.log10.floor, top = [1, 2, 5, 10].detect { |k| k * step >= peak } * step;
		^[top.neg, top]
	}

	// Ticks below r; the title at the right end of the tick row (ticks under it are left out).
	prAxisX { |r, range, font, title, isTime = false|
		var step = this.prStep(range[1] - range[0], (r.width / 90).max(2)), v, x, decimals;
		var titleLeft = r.right - (title.size * 6);  // title nil: ticks only
		decimals = max(0, step.log10.floor.neg).asInteger;
		v = (range[0] / step).ceil * step;
		Pen.strokeColor = Color.gray(0.6); Pen.width = 1;
		while { v <= (range[1] + (step * 1e-6)) } {
			x = if(isTime) { r.right - (v.neg / this.historyS * r.width) } {
				r.left + ((v - range[0]) / (range[1] - range[0]) * r.width)
			};
			Pen.line(x @ r.bottom, x @ (r.bottom + 4)); Pen.stroke;
			if(title.notNil and: { x + 26 < titleLeft }) {
				Pen.stringAtPoint(this.prFormat(v, decimals), (x - 12) @ (r.bottom + 5), font, Color.gray(0.2))
			};
			v = v + step;
		};
		title !? { Pen.stringAtPoint(title, titleLeft @ (r.bottom + 5), font, Color.black) };
	}

	prAxisY { |r, range, font|
		var step = this.prStep(range[1] - range[0], (r.height / 28).max(2)), v, y, decimals;
		decimals = max(0, step.log10.floor.neg).asInteger;
		v = (range[0] / step).ceil * step;
		Pen.strokeColor = Color.gray(0.6); Pen.width = 1;
		while { v <= (range[1] + (step * 1e-6)) } {
			y = r.bottom - ((v - range[0]) / (range[1] - range[0]) * r.height);
			Pen.line((r.left - 4) @ y, r.left @ y); Pen.stroke;
			Pen.stringInRect(this.prFormat(v, decimals), Rect(0, y - 7, r.left - 6, 14), font, Color.gray(0.2),
				\right);
			v = v + step;
		};
	}

	prStep { |span, maxTicks|
		var raw = span.abs.max(1e-12) / maxTicks, mag = 10 ** raw.log10.floor;
		^[1, 2, 5, 10].detect { |k| k * mag >= raw } * mag
	}

	// value with `decimals` digits after the point, without float noise.
	prFormat { |value, decimals|
		var scale, scaled, whole, frac, text;
		if(value.isNil) { ^"-" };
		if(value.isNaN) { ^"nan" };
		decimals = decimals.asInteger.clip(0, 9);
		scale = 10 ** decimals;
		scaled = (value.abs * scale).round;
		whole = (scaled / scale).floor.asInteger;
		text = whole.asString;
		if(decimals > 0) {
			frac = (scaled - (whole * scale)).round.asInteger.asString;
			text = text ++ "." ++ String.fill(decimals - frac.size, $0) ++ frac;
		};
		^if(value < 0 and: { scaled > 0 }) { "-" ++ text } { text }
	}
}
