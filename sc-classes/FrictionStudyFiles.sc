// The session folder's text files: JSON for the manifest, CSV lines appended and flushed one at a
// time (a killed sclang loses no line already given), and the checks of a folder before a session.
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

	// Appends fields as one CSV line to path and flushes it to the operating system before it
	// returns; writes header first when the file is new.
	*appendCsv { |path, fields, header|
		var isNew = File.exists(path).not, file = File(path, "a");
		if(file.isOpen.not) { Error("FrictionStudy: cannot write %".format(path)).throw };
		if(isNew and: { header.notNil }) { file.write(header.join(",") ++ "\n") };
		file.write(fields.collect { |f| this.csvField(f) }.join(",") ++ "\n");
		file.flush;
		file.close;
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
