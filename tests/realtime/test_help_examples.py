"""Every code:: example of every help file runs on a booted realtime server (JACK dummy).

Each block is split as a user evaluates it in the IDE: a region between a line holding only "("
and a line starting with ")" is one piece, every other non-blank line is one piece. (If a piece
alone does not compile, the whole block runs as one piece.) Pieces run in order on AppClock, a
short pause after each; a block gets ~1.5 s. Blocks of a file run in order, so later ones see the
~variables and synths of earlier ones; after the last block of a file, s.freeAll and every device
slot is closed (FREE_EACH_BLOCK = True frees nodes after every block instead).

A block whose first line is a comment beginning "// needs " ("// needs a mouse") needs hardware
this machine may not have: it is skipped (it still has to compile: tests/scenes/test_help.py).

The test fails on any sclang error (thrown by a piece, or posted as ERROR from a routine or a
responder it started), on a piece that does not compile, and when scsynth exits.
GUI examples (.plot, .scope, Window) run headless with QT_QPA_PLATFORM=offscreen.
"""
import os
import re
from pathlib import Path

from kfharness import paths, sclang
from kfharness.jack import JackServer

HELP_DIR = Path(os.environ.get("KF_HELP_DIR") or paths.REPO_DIR / "HelpSource")
PIECE_PAUSE_S = 0.3
BLOCK_TIME_S = 1.5
# Nodes are freed after each file, not after each block: the guides are sessions (a pilot started
# in one block is steered by the next ones), which s.freeAll after every block would break into
# "/n_set Node not found". Devices are closed after each file too.
FREE_EACH_BLOCK = False

RUNNER = r"""
var files = [%(files)s];
var codeBlocks, piecesOf, serverAlive, restart;
codeBlocks = { |node|
	if(node.id == \CODEBLOCK) { [node.text] } {
		(node.children ? []).collect(codeBlocks).flatten(1)
	}
};
// The pieces a user evaluates one by one: "(" ... ")" regions and single lines.
piecesOf = { |code|
	var lines = code.split($\n), pieces = List.new, i = 0;
	var headOf = { |line|
		var trimmed = line.stripWhiteSpace, comment = trimmed.find("//");
		if(comment.notNil) { trimmed = trimmed.keep(comment).stripWhiteSpace };
		trimmed
	};
	while { i < lines.size } {
		var line = lines[i], j;
		if(headOf.(line) == "(") {
			j = i + 1;
			while { j < lines.size and: { lines[j].beginsWith(")").not } } { j = j + 1 };
			pieces.add(lines.copyRange(i, j.min(lines.size - 1)).join($\n));
			i = j + 1;
		} {
			if(headOf.(line).notEmpty) { pieces.add(line) };
			i = i + 1;
		};
	};
	if(pieces.any { |p| p.compile.isNil }) {
		"KF-HELP-NOTE a piece does not compile alone; the block runs as a whole".postln;
		pieces = [code];
	};
	pieces
};
serverAlive = { s.pid.notNil and: { s.pid.pidRunning } };
restart = {
	"KF-HELP-SERVER-DIED".postln;
	s.quit;
	1.wait;
	s.bootSync;
	"KF-SCSYNTH-PID %%".format(s.pid).postln;
};

files.do { |path|
	var doc = SCDoc.parseFileFull(path), blocks;
	if(doc.isNil) { "KF-HELP-PARSE-FAILED %%".format(path).postln } {
		blocks = codeBlocks.(doc);
		"KF-HELP-FILE %% (%% blocks)".format(path, blocks.size).postln;
		blocks.do { |code, b|
			var pieces = piecesOf.(code), start = Main.elapsedTime;
			if(code.stripWhiteSpace.beginsWith("// needs ")) {
				"KF-HELP-SKIPPED %% %% (needs hardware)".format(path, b).postln;
				pieces = [];
				start = start - %(block_time)f;  // no time to wait for
			};
			pieces.do { |piece, p|
				var fn = piece.compile;
				"KF-HELP-PIECE %% %% %%".format(path, b, p).postln;
				if(fn.isNil) { "KF-HELP-COMPILE-FAILED %% %% %%".format(path, b, p).postln } {
					try { fn.value } { |error|
						error.reportError;
						"KF-HELP-THROWN %% %% %%".format(path, b, p).postln;
					};
				};
				%(piece_pause)f.wait;
			};
			if(pieces.notEmpty) { (%(block_time)f - (Main.elapsedTime - start)).max(0.2).wait };
			"KF-HELP-BLOCK-END %% %%".format(path, b).postln;
			if(serverAlive.().not) { restart.() } {
				if(%(free_each_block)s) { s.freeAll; s.sync };
			};
		};
		s.freeAll;
		16.do { |i| s.sendMsg('/cmd', 'kfClose', i) };
		s.sync;
		Window.allWindows.do(_.close);
		0.2.wait;
		if(serverAlive.().not) { restart.() };
		"KF-HELP-FILE-DONE %%".format(path).postln;
	};
};
"KF-HELP-ALL-DONE".postln;
"""

PROBLEM_PATTERNS = [
    (re.compile(r"^ERROR"), "sclang error"),
    (re.compile(r"^KF-HELP-THROWN"), "a piece threw"),
    (re.compile(r"^KF-HELP-COMPILE-FAILED"), "a piece does not compile"),
    (re.compile(r"^KF-HELP-PARSE-FAILED"), "the help file does not parse"),
    (re.compile(r"^KF-HELP-SERVER-DIED"), "scsynth exited"),
    (re.compile(r"^Server '\w+' exited"), "scsynth exited"),
    (re.compile(r"^(Segmentation fault|Aborted|terminate called)"), "a crash"),
    # Every line the device commands post, but kfStatus, reports a failed command.
    (re.compile(r"^kf(OpenSim|OpenReplay|Record|Close)\b.*: "), "a device command failed"),
    (re.compile(r"^kfBoard\w+: "), "a board command failed"),
    (re.compile(r"RT memory allocation failed"), "RT memory allocation failed"),
]
NOTE_PATTERNS = [re.compile(p) for p in (r"^FAILURE IN SERVER", r"^WARNING", r"^KF-HELP-NOTE",
                                         r"no device is open", r"^kf\w+: ")]


def test_every_help_example_runs_on_a_realtime_server():
    files = sorted(HELP_DIR.rglob("*.schelp"))
    assert files, "no help files"
    with JackServer() as jack:
        run = sclang.run_with_server(RUNNER % dict(files=", ".join(sclang.sc_string(f) for f in files),
                                          piece_pause=PIECE_PAUSE_S, block_time=BLOCK_TIME_S,
                                          free_each_block=str(FREE_EACH_BLOCK).lower()),
                            jack, name="help", timeout=240)
        jack_alive = jack.alive()

    # Attribute every line to the piece that was running when it was posted.
    problems, notes = [], []
    where = "(before the first example)"
    finished = False
    for line in run.output.splitlines():
        if line.startswith("KF-HELP-PIECE ") or line.startswith("KF-HELP-FILE "):
            where = line.split(" ", 1)[1]
        if line.startswith("KF-HELP-ALL-DONE"):
            finished = True
        if finished:
            continue  # the harness's own server quit
        for pattern, what in PROBLEM_PATTERNS:
            if pattern.search(line):
                problems.append(f"{where}: {what}: {line}")
                break
        else:
            if any(p.search(line) for p in NOTE_PATTERNS):
                notes.append(f"{where}: {line}")

    summary = paths.work_dir() / "help-examples-summary.txt"
    summary.write_text("\n".join(["PROBLEMS"] + problems + ["", "NOTES"] + notes) + "\n")
    print(f"log {run.log_path}\nsummary {summary}")
    print("\n".join(notes))
    assert finished and run.ok, f"the runner did not finish (rc {run.returncode}), log {run.log_path}:\n{run.output[-5000:]}"
    assert jack_alive, "jackd died during the examples"
    for f in files:
        assert f"KF-HELP-FILE-DONE {f}" in run.output, f"{f} did not run"
    assert not problems, "help examples with problems:\n" + "\n".join(problems)
