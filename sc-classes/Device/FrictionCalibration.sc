// A friction board's calibration table: measured force (N) at drive levels (0..1 of the
// board's full-scale current), and the file the server's kfBoardCalibrate loads
// ("kf-calibration 1", docs/calibration-format.md). The server inverts it (force -> drive);
// driveFor does the same here, to check a table before using it. A table names the serial of
// the board it was measured on: the server loads it onto that board only.
FrictionCalibration {
	var <points, <>serial, <path;

	// points: [[drive, forceN], ...], drives ascending in 0..1, forces never descending.
	*new { |points, serial| ^super.new.prInit(points, serial) }

	// An uncalibrated board: drive 0 -> minForce, 1 -> maxForce.
	*linear { |minForce = 0.14, maxForce = 1.4| ^this.new([[0, minForce], [1, maxForce]]) }

	// The drive levels to measure at: n of them, evenly from 0 to 1.
	*drives { |n = 11|
		if(n.isInteger.not or: { n < 2 }) { Error("FrictionCalibration.drives: n must be an Integer >= 2").throw };
		^(0..n - 1) / (n - 1)
	}

	*read { |path|
		var lines, header, pts = List.new, ser;
		path = path.standardizePath;
		if(File.exists(path).not) { Error("FrictionCalibration.read: no such file: %".format(path)).throw };
		lines = File.readAllString(path).split($\n);
		lines.do { |line, i|
			var fields;
			line = line.split($#)[0].stripWhiteSpace;
			fields = line.split($ ).reject(_.isEmpty);
			if(fields.notEmpty) {
				case
				{ header.isNil } {
					if(fields != ["kf-calibration", "1"]) {
						Error("FrictionCalibration.read: %: line %: expected the header \"kf-calibration 1\"".format(
							path, i + 1)).throw
					};
					header = true
				}
				{ fields[0] == "serial" } {
					if(fields.size != 2) {
						Error("FrictionCalibration.read: %: line %: expected \"serial <the board's serial>\"".format(
							path, i + 1)).throw
					};
					ser = fields[1]
				}
				{
					if(fields.size != 2) {
						Error("FrictionCalibration.read: %: line %: expected drive and force".format(path, i + 1)).throw
					};
					pts.add(fields.collect(_.asFloat))
				}
			}
		};
		if(header.isNil) { Error("FrictionCalibration.read: %: empty file".format(path)).throw };
		^this.new(pts.asArray, ser).prSetPath(path)
	}

	// The file names the board (serial): the server refuses a table without one, or another
	// board's, so write refuses to make such a file.
	write { |path|
		var file;
		if(serial.isNil) {
			Error("FrictionCalibration.write: give the serial of the board it was measured on " ++
				"(FrictionCalibration(points, serial) or .serial_; the board's status shows it)").throw
		};
		path = path.standardizePath;
		file = File(path, "w");
		if(file.isOpen.not) { Error("FrictionCalibration.write: cannot write %".format(path)).throw };
		file.write("kf-calibration 1\n");
		serial !? { file.write("serial %\n".format(serial)) };
		file.write("# drive (0..1 of full-scale current)  force (N)\n");
		points.do { |p| file.write("% %\n".format(p[0].asStringPrec(17), p[1].asStringPrec(17))) };
		file.close;
		this.prSetPath(path);  // the argument hides the variable of the same name
	}

	// The least drive that gives forceN; clamped to the table's ends.
	driveFor { |forceN|
		var i;
		if(forceN <= points.first[1]) { ^points.first[0] };
		if(forceN >= points.last[1]) { ^points.detect { |p| p[1] >= points.last[1] }[0] };
		i = points.detectIndex { |p| p[1] >= forceN };
		if(points[i][1] == forceN) { ^points[i][0] };
		^forceN.linlin(points[i - 1][1], points[i][1], points[i - 1][0], points[i][0])
	}

	forceFor { |drive|
		var i;
		if(drive <= points.first[0]) { ^points.first[1] };
		if(drive >= points.last[0]) { ^points.last[1] };
		i = points.detectIndex { |p| p[0] >= drive };
		^drive.linlin(points[i - 1][0], points[i][0], points[i - 1][1], points[i][1])
	}

	printOn { |stream|
		stream << this.class.name << "(" << points.size << " points" << (serial !? { ", " ++ serial } ? "") << ")"
	}

	prSetPath { |argPath| path = argPath }

	prInit { |argPoints, argSerial|
		if(argPoints.isArray.not or: { argPoints.isEmpty }) {
			Error("FrictionCalibration: points must be a non-empty Array of [drive, forceN] pairs").throw
		};
		argPoints.do { |p, i|
			if(p.isArray.not or: { p.size != 2 } or: { p.any { |v| v.isNumber.not } }) {
				Error("FrictionCalibration: point % is not a [drive, forceN] pair: %".format(i + 1, p)).throw
			};
			if(p[0] < 0 or: { p[0] > 1 }) {
				Error("FrictionCalibration: point %: drive % is not in 0..1".format(i + 1, p[0])).throw
			};
			if(p[1] < 0 or: { p[1] == inf }) {
				Error("FrictionCalibration: point %: force % N is not a finite force >= 0".format(i + 1, p[1])).throw
			};
			if(i > 0) {
				if(p[0] <= argPoints[i - 1][0]) {
					Error("FrictionCalibration: point %: drive % does not ascend (previous %)".format(
						i + 1, p[0], argPoints[i - 1][0])).throw
				};
				if(p[1] < argPoints[i - 1][1]) {
					Error("FrictionCalibration: not monotone: point % has % N at drive %, less than % N at drive %"
						.format(i + 1, p[1], p[0], argPoints[i - 1][1], argPoints[i - 1][0])).throw
				};
			};
		};
		if(argSerial.notNil and: { argSerial.isString.not and: { argSerial.isKindOf(Symbol).not } }) {
			Error("FrictionCalibration: serial must be a String or nil, got %".format(argSerial)).throw
		};
		if(argSerial.notNil and: { argSerial.asString.isEmpty or: { argSerial.asString.any(_.isSpace) } }) {
			Error("FrictionCalibration: serial must be one word (the board's USB serial), got \"%\"".format(
				argSerial)).throw
		};
		points = argPoints.collect { |p| p.collect(_.asFloat) };
		serial = argSerial !? { argSerial.asString };
	}
}
