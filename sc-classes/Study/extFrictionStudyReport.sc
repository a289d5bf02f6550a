// The report of a study's sessions, from sclang: the extension's own Python (its python/kfstudy
// folder, installed with the classes) run by python3 with numpy, pandas, matplotlib, scipy and soundfile.
// It writes report.md with PNG figures and CSV files beside it into a folder, and report.log (what
// python3 said). A missing package is named, with the Debian packages that hold them.
+ FrictionStudy {
	// The folder holding the report's Python package (kfstudy).
	*pythonDir { ^KineticFriction.extensionDir +/+ "python" }

	// The python3 the report runs: Debian's (/usr/bin/python3, where apt puts python3-scipy and the
	// others) where there is one, else the python3 the shell finds.
	*defaultPython { ^if(File.exists("/usr/bin/python3")) { "/usr/bin/python3" } { "python3" } }

	// Reports every session in sessionsFolder (the folder given to run: one folder per participant)
	// into reportFolder (made if needed). Call it inside a Routine: it waits for python3 (seconds)
	// and returns the path of report.md; a failure throws an Error with the reason.
	*report { |sessionsFolder, reportFolder, python|
		var where = "FrictionStudy.report", log, done = Condition(false), status, command, said;
		if(thisThread.isKindOf(Routine).not) {
			Error("%: call it inside a Routine (fork): the report takes seconds".format(where)).throw
		};
		if(sessionsFolder.isString.not or: { File.exists(sessionsFolder.standardizePath).not }) {
			Error("%: sessionsFolder must be an existing folder, got %".format(where, sessionsFolder.cs)).throw
		};
		sessionsFolder = sessionsFolder.standardizePath;
		if(PathName(sessionsFolder).folders.any { |f| File.exists(f.fullPath +/+ "manifest.json") }.not) {
			Error("%: no session in % (a session is a folder with a manifest.json, made by run)".format(where,
				sessionsFolder)).throw
		};
		FrictionStudyFiles.checkWritable(reportFolder, where);
		reportFolder = reportFolder.standardizePath;
		python = python ?? { this.defaultPython };
		log = reportFolder +/+ "report.log";
		// -B: no byte code written into the extension folder.
		command = "PYTHONPATH=%\"${PYTHONPATH:+:$PYTHONPATH}\" % -B -m kfstudy % % > % 2>&1".format(
			this.pythonDir.shellQuote, python.shellQuote, sessionsFolder.shellQuote, reportFolder.shellQuote,
			log.shellQuote);
		command.unixCmd({ |exitCode| status = exitCode; done.test = true; done.signal }, false);
		done.wait;
		said = if(File.exists(log)) { File.readAllString(log) } { "" };
		case
			{ status == 0 } { said.postln; ^reportFolder +/+ "report.md" }
			{ status == 127 } {
				Error("%: % was not found: the report runs python3 with numpy, pandas, matplotlib, scipy and "
					"soundfile (on Debian or Ubuntu: sudo apt-get install python3 python3-numpy python3-pandas "
					"python3-matplotlib python3-scipy python3-soundfile)".format(where, python)).throw
			}
			{ Error("%: the report failed (% exit %): %".format(where, python, status,
				said.split($\n).reject(_.isEmpty).keep(-12).join("\n"))).throw }
	}
}
