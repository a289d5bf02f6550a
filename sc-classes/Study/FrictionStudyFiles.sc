// The session folder's text files: JSON for the manifest, CSV lines appended and flushed one at a
// time, each with its check (a killed sclang loses no line already given, and a cut one is told
// from a whole one), and the checks of a folder before a session.
FrictionStudyFiles {
	// obj (Event, Array, String, Symbol, number, Boolean, nil) as JSON text; Event keys sorted.
	*json { |obj|
		^case
			{ obj.isNil } { "null" }
			{ obj == true } { "true" }
			{ obj == false } { "false" }
			{ obj.isKindOf(Dictionary) } {
				"{" ++ obj.keys.asArray.sort { |a, b| a.asString < b.asString }.collect { |k|
					this.json(k.asString) ++ ": " ++ this.json(obj[k])
				}.join(", ") ++ "}"
			}
			{ obj.isString } { "\"" ++ this.prEscape(obj) ++ "\"" }
			{ obj.isKindOf(Symbol) } { this.json(obj.asString) }
			{ obj.isSequenceableCollection } { "[" ++ obj.collect { |v| this.json(v) }.join(", ") ++ "]" }
			{ obj.isNumber } { if(obj.isNaN or: { obj.abs == inf }) { "null" } { obj.asString } }
			{ this.json(obj.asString) }
	}

	// A CSV field: quoted, its quotes doubled (free text may hold commas, quotes, new lines).
	*csvField { |value| ^"\"" ++ value.asString.replace("\"", "\"\"") ++ "\"" }

	// Appends fields as one CSV line to path, ended by its check field (the line's Adler-32 before
	// it: python/kfstudy/checked_csv.py skips a row whose check fails, naming its line), and
	// flushes it to the operating system before it returns; writes header (and the check
	// column) first when the file is new. A file whose last line was cut (a crash, a full disk)
	// gets a line break first: the cut row stays on a line of its own, the new one is whole.
	*appendCsv { |path, fields, header|
		var isNew = File.exists(path).not, cut = isNew.not and: { this.prEndsCut(path) }, file, row;
		file = File(path, "a");
		if(file.isOpen.not) { Error("FrictionStudy: cannot write %".format(path)).throw };
		if(isNew and: { header.notNil }) { file.write((header ++ [\check]).join(",") ++ "\n") };
		row = fields.collect { |f| this.csvField(f) }.join(",");
		if(cut) { file.write("\n") };
		file.write(row ++ "," ++ this.csvField(this.check(row)) ++ "\n");
		file.flush;
		file.close;
	}

	// A row's check: the Adler-32 (RFC 1950, as Python's zlib.adler32) of its bytes, 8 hex digits.
	*check { |text|
		var a = 1, b = 0;
		text.do { |c| a = (a + (c.ascii % 256)) % 65521; b = (b + a) % 65521 };
		^b.asHexString(4) ++ a.asHexString(4)
	}

	*writeText { |path, text|
		var file = File(path, "w");
		if(file.isOpen.not) { Error("FrictionStudy: cannot write %".format(path)).throw };
		file.write(text);
		file.flush;
		file.close;
	}

	// The folder exists or can be made, and a file can be written in it; else the reason.
	*checkWritable { |folder, where|
		var probe, file;
		if(folder.isString.not or: { folder.isEmpty }) {
			Error("%: folder must be a path (String), got %".format(where, folder)).throw
		};
		folder = folder.standardizePath;
		try { File.mkdir(folder) } { |error|
			Error("%: the folder % cannot be written (%)".format(where, folder, error.errorString)).throw
		};
		probe = folder +/+ ".kf-write-probe";
		file = File(probe, "w");
		if(file.isOpen.not) { Error("%: the folder % cannot be written".format(where, folder)).throw };
		file.close;
		File.delete(probe);
	}

	// True if the file's last byte is not a line break (its last line was cut).
	*prEndsCut { |path|
		var file = File(path, "rb"), cut = false;
		if(file.isOpen) {
			if(file.length > 0) { file.seek(-1, 2); cut = file.getChar != $\n };
			file.close
		};
		^cut
	}

	// Local date and time, ISO 8601 (seconds).
	*now { ^Date.getDate.format("%Y-%m-%dT%H:%M:%S") }

	*prEscape { |string|
		^string.as(Array).collect { |c|
			case
				{ c == $" } { "\\\"" }
				{ c == $\\ } { "\\\\" }
				{ c == $\n } { "\\n" }
				{ c == $\t } { "\\t" }
				{ c.ascii < 32 } { "\\u%".format(c.ascii.asHexString(4)) }
				{ c.asString }
		}.join
	}
}
