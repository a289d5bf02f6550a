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

	// The rows of a CSV that appendCsv wrote, each an Event of the header's names (Symbols) to
	// its fields (Strings, the check left out), in the file's order. As kfstudy's checked_csv
	// reads them: a record is the shortest run of lines from a row's start whose quotes balance
	// (free text keeps its line breaks); one whose check fails (cut, changed) is left out, its
	// first line's number (the header is line 1) added to damaged (a List, or nil), and the
	// next line is tried as a row's start. No file: no rows.
	*readCsv { |path, damaged|
		var lines, header, rows = [], start = 1;
		if(File.exists(path).not) { ^[] };
		lines = File.readAllString(path).split($\n);
		if(lines.last == "") { lines.pop };
		if(lines.isEmpty) { ^[] };
		header = this.prFields(lines[0]).drop(-1).collect(_.asSymbol);
		while { start < lines.size } {
			var end = start, record = lines[start], fields;
			while { record.occurrencesOf($").odd and: { end + 1 < lines.size } and: { end - start < 64 } } {
				end = end + 1;
				record = record ++ "\n" ++ lines[end]
			};
			fields = this.prCheckedFields(record, header.size);
			if(fields.notNil) {
				rows = rows.add(Event.newFrom([header, fields].flop.flatten));
				start = end + 1
			} {
				damaged !? { damaged.add(start + 1) };
				start = start + 1
			}
		};
		^rows
	}

	// A record's fields if its check holds and it has width of them (the check left out), else nil.
	*prCheckedFields { |record, width|
		var tail = 11, body, fields;  // ,"XXXXXXXX"
		if(record.size <= tail or: { record.occurrencesOf($").odd }) { ^nil };
		body = record.copyRange(0, record.size - tail - 1);
		if(this.check(body) != record.copyRange(record.size - 9, record.size - 2)) { ^nil };
		fields = this.prFields(body);
		^if(fields.size == width) { fields } { nil }
	}

	// One record's fields: quoted ("" a quote inside) or bare, split at commas outside quotes.
	*prFields { |record|
		var fields = [], field = String.new, quoted = false, i = 0;
		while { i < record.size } {
			var c = record[i];
			case
				{ quoted and: { c == $" } and: { record[i + 1] == $" } } { field = field.add(c); i = i + 1 }
				{ c == $" } { quoted = quoted.not }
				{ quoted.not and: { c == $, } } { fields = fields.add(field); field = String.new }
				{ field = field.add(c) };
			i = i + 1
		};
		^fields.add(field)
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
