// FrictionView's drawing: the layout of its three panels (surface, speed, force), the signal
// under the puck at the view's zoom, the strip charts and their axes. Drawn in the userView's
// drawFunc from the view's state (range, signal pyramid, the monitor's frames); nothing here
// talks to the server.
+ FrictionView {

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
		drawn[\header] = this.prDrawHeader(lay[\header], font);
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
		// The rate the device plays force at: the force's part above half of it never reaches the puck.
		this.forceRateHz !? { |hz|
			text = text ++ if(forceN.notNil) { " at" } { "   force at" };
			text = text ++ " % kHz".format(this.prFormat(hz / 1000, if(hz % 1000 == 0) { 0 } { 3 }))
		};
		if(pilot.notNil and: { monitor.running.not }) { text = text ++ "   (the pilot is not playing)" };
		text = text ++ "   % samples/mm, origin % mm".format(this.prFormat(spm, if(spm.frac == 0) { 0 } { 3 }),
			this.prFormat(this.origin, 2));
		Pen.stringInRect(text, r, font, Color.black, \left);
		^text
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
