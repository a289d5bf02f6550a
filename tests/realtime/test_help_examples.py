"""Every code:: example of every help file runs on a booted realtime server (JACK dummy), at the
pace a person evaluates it, fails when it fails, and posts what its text says it posts.

Each block is split as a user evaluates it in the IDE: a region between a line holding only "("
and a line starting with ")" is one piece, every other non-blank line is one piece. (If a piece
alone does not compile, the whole block runs as one piece.) Pieces run in order on AppClock and
each piece's value is posted as "-> value", as the IDE does. After each piece the runner waits as a
person would before the next: a short pause; for a boot (or reboot) to finish, ServerTree
included; and for the routines the piece started (fork, Routine.play) to end, at most
FORK_WAIT_MAX_S (a routine still running then is one a person leaves running). A block gets
BLOCK_TIME_S. Blocks of a file run in order, so later ones see the ~variables and synths of earlier
ones; after the last block of a file, s.freeAll and every device slot is closed (FREE_EACH_BLOCK =
True frees nodes after every block instead).

The guides (every file outside HelpSource/Classes: Guides/ and Overviews/) are followed as one
user follows them: all in one sclang on one server, the overview first, then the guides in the
order it links them (guide_order). In a guide, a line about a closed device ("no device is open
at index 3": a synth reading a slot its example closed, or started before its device) fails the
block, and its last block is its clean-up: a node still on the server CLEANUP_WATCH_S after it,
but the default group, fails the guide. The class help files are shared out over the other servers (shards_of), files
naming one temp file in the same one. After every block of every file the server must still have
its default group (node 1).

A block whose first line is a comment beginning "// needs " ("// needs a mouse") needs hardware
this machine may not have: it is skipped (it still has to compile: tests/scenes/test_help.py).

An example fails (FAILURES) on a line of the server or sclang saying something went wrong:
"FAILURE IN SERVER", "Node <n> not found", a line starting "ERROR" (sclang errors, and the
refusals FrictionAnswers posts), "*** ERROR", an sclang exception (a piece that threw,
DoesNotUnderstand, a call stack), a piece that does not compile, a command the server refused
("kfZero: no device is open at index 7"), scsynth exiting or crashing, a server without its
default group; the whole run fails on a non-zero exit or a time-out, naming the piece that was
running. Each failure names the file, the block (SCDoc's code block number, from 0, and its first
line) and the offending line.

What an example posts, writes or fails with is checked against what its comments say, in words a
user reads as ordinary comments (ANNOTATIONS, anywhere in a // comment):

  // -> <value>                a piece's value: the line "-> <value>" is posted, as in the IDE
  // posts "<text>"            a line containing <text> is posted (also "this posts "<text>"")
  // fails with "<text>"       this block must post a failure line containing <text>; any other
                               failure line still fails it
  // writes <file> (<n> channels, <d> s)
                               the file (in Platform.defaultTempDir unless absolute) is written
                               during the run; a WAV file has n channels and lasts d s (both
                               optional); a "*" in it stands for a part the example makes up
  // the force reaches <N> N   device slot 0 commands that force (or more) at some time in the
                               piece's time (polled 20 times a second, from 0.1 s after it starts;
                               up to CLAIM_WAIT_MAX_S more while not reached)
  // the force stays at <N> N  ... and only that force, throughout
  // the force stays between <A> and <B> N
                               ... and only forces from A to B, throughout (a crossfade's bound)
  // no jump in the sound      the speakers' sound has no step between two samples in the piece's
                               time from 0.5 s after it starts (no sample changes by more than
                               twice the changes beside it; a kink is no jump): a claim for a
                               block's last piece, whose time runs to the block's end
  // sound on the outputs      the speakers (outputs 0 and 1) are heard at some time from this
                               piece on, until the block's end (the piece not yet heard is
                               listened to up to CLAIM_WAIT_MAX_S more: a puck held at a turn)
  // silence on the outputs    the speakers get nothing, no DC either, at the end of the piece's
                               time (until the next piece; the last one's until the block's end)
                               (a line holding only a comment goes with the next piece; the
                               meter's three claims are checked in the release pass: METER)

Numbers in <value> and <text> match to the precision written ("0.56" matches 0.5612, not 0.57).
A piece's time lasts until what judges it has come in (READINGS_WAIT_MAX_S): on a loaded machine
sclang may stand still through a whole pause. A block's output is what is posted from its start to
the end of its file: an NRT render or a server reply may come after the block's time on a loaded
machine. The test markers of earlier
versions ("// posts:", "// expect error:", "// writes:") are refused, so that none is left unread.
test_broken_examples_are_reported shows that each rule fails a broken example.
"""
import os
import re
import shutil
import threading
import time
from concurrent.futures import ThreadPoolExecutor
from contextlib import ExitStack
from pathlib import Path

import pytest

from kfharness import paths, procs, sclang
from kfstudy import readers
from conftest import performer_jack
from kfharness.jack import JackServer

HELP_DIR = Path(os.environ.get("KF_HELP_DIR") or paths.REPO_DIR / "HelpSource")
# KF_HELP_FILES: only these help files (paths under HELP_DIR without .schelp, space-separated):
# the sanitized plugin's run takes those whose plugin lines no other of its tests runs
# (tests/realtime/sanitized-help-files.txt). Unset: every file.
SELECTED = os.environ.get("KF_HELP_FILES", "").split()

PIECE_PAUSE_S = 0.3
BLOCK_TIME_S = 1.2
# A person waits for a fork's waits; one still running after this is left running. (The Study
# guide's report, a fork around FrictionStudy.report's Python, took 13 s beside a build.)
FORK_WAIT_MAX_S = 30.0
# The soak after the guides: runs of each threshold procedure in one Routine (QUEST+ 0.25 s a run
# here, the constant stimuli's fit 0.3 s, a staircase 1 ms), about 25 s in all. sclang's alone: the
# pass against the sanitized plugin (KF_SERVER_PRELOAD) leaves it out, as it would add nothing.
SOAK_RUNS = {"questPlus": 60, "constantStimuli": 30, "staircase2down": 200, "staircase3down": 200}
SOAK = not os.environ.get("KF_SERVER_PRELOAD")
# The meter on the outputs and the claims it checks (sound, silence, no jump): the release pass's.
# The pass against the sanitized plugin leaves them out: it adds nothing to what the examples play,
# and its one run with the meter ended in "terminate called without an active exception" from
# scsynth as it quit for a reboot (a thread destroyed unjoined at exit, as in SuperCollider's issue
# 6288; whose thread, not found), in the broken-examples test of a fresh clone.
METER = not os.environ.get("KF_SERVER_PRELOAD")
METER_CLAIMS = ("sound", "silence", "no jump")
# A boot takes ~1 s here; a server not back after this is a failure.
BOOT_WAIT_MAX_S = 30.0
# A piece's time lasts until what judges it has come in: a reading of the meter in its last 0.15 s
# (it sends 20 a second) and, when its force is polled, FORCE_READINGS readings from 0.1 s after its
# start (4 come in the 0.3 s pause). Beside two CPU hogs and four servers, sclang stood still
# through a whole piece's pause: nothing came in it (no meter reading, 0 of the force) and its
# claim was judged on nothing (a fresh clone at 6c6d957). At most this long more.
READINGS_WAIT_MAX_S = 2.0
FORCE_READINGS = 3
# A piece that claims "sound on the outputs" and is not yet heard is listened to this long more, and
# one that claims "the force reaches <N> N" not yet reached is polled this long more. A
# simulated hand pulls its puck through a spring (20 N/m): at a turn of its sweep the puck stands
# still until the hand's lag has turned from +F/k to -F/k, 2F / (k v). With the pilot's 0.5 N that
# is 2.0 s at the LiveCoding guide's 25 mm/s and 3.3 s at the Patterns guide's 15 mm/s; measured,
# the LiveCoding guide's zoom after its reboot was silent for its whole 0.5 s time (the puck held at
# a turn) beside two CPU hogs. A simulated device opened again starts with its puck at rest until
# the lag reaches F/k (7 mm at the minimum 0.14 N, 0.28 s at 25 mm/s): the guide's pilot played
# after its reboot commanded its floor, 0.14 N, for all 8 readings of its piece (a fresh clone at
# bc339b4), the puck resting on a zero of the sine.
CLAIM_WAIT_MAX_S = 4.0
# After a guide's clean-up: how long the runner listens for synths still running.
CLEANUP_WATCH_S = 1.0
# Nodes are freed after each file, not after each block: the guides are sessions (a pilot started
# in one block is steered by the next ones), which s.freeAll after every block would break into
# "/n_set Node not found". Devices are closed after each file too.
FREE_EACH_BLOCK = False
# The class help files run in this many servers beside the guides' (each its own jackd, scsynth
# and sclang): a run is mostly the examples' pauses, not work, so they share two cores well.
SHARDS = 3
TEMP_NAME = re.compile(r'defaultTempDir\s*\+/\+\s*"([^"]+)"')
CODE_BLOCK = re.compile(r"^code::[ \t]*$(.*?)^::", re.M | re.S)
LINK = re.compile(r"link::((?:Guides|Overviews)/[^#:]+)::")

RUNNER = r"""
var files = [%(files)s], guides = [%(guides)s];
var codeBlocks, piecesOf, serverAlive, restart, routinesQueued, waitLikeAPerson, hasDefaultGroup, nodesBesidesDefault;
var headOf, runPiece, compileKeepingFrame, pieceStack, startMeter, meterLevels = List.new, levelsSince, meterAtEnd, pollForce, forcesSince;
var waitForReadings, waitForClaim;
var treePending = false;
codeBlocks = { |node|
	if(node.id == \CODEBLOCK) { [node.text] } {
		(node.children ? []).collect(codeBlocks).flatten(1)
	}
};
// A line's code: without its comment and the white space around.
headOf = { |line|
	var trimmed = line.stripWhiteSpace, comment = trimmed.find("//");
	if(comment.notNil) { trimmed = trimmed.keep(comment).stripWhiteSpace };
	trimmed
};
// The pieces a user evaluates one by one: "(" ... ")" regions and single lines.
piecesOf = { |code|
	var lines = code.split($\n), pieces = List.new, i = 0;
	// A line holding only a comment says what the piece after it does: it goes with that piece
	// (with the last one at the block's end).
	var pending = "", add = { |piece| pieces.add(pending ++ piece); pending = "" };
	while { i < lines.size } {
		var line = lines[i], j;
		if(headOf.(line) == "(") {
			j = i + 1;
			while { j < lines.size and: { lines[j].beginsWith(")").not } } { j = j + 1 };
			add.(lines.copyRange(i, j.min(lines.size - 1)).join($\n));
			i = j + 1;
		} {
			case
			{ headOf.(line).notEmpty } { add.(line) }
			{ line.find("//").notNil } { pending = pending ++ line ++ "\n" };
			i = i + 1;
		};
	};
	if(pending.notEmpty) { if(pieces.isEmpty) { pieces.add(pending) } { pieces[pieces.size - 1] = pieces.last ++ "\n" ++ pending } };
	if(pieces.any { |p| p.compile.isNil }) {
		"KF-HELP-NOTE a piece does not compile alone; the block runs as a whole\n".post;
		pieces = [code];
	};
	pieces
};
// SuperCollider 3.13 frees a function's frame as it returns when the function makes no closure,
// though a method it called may live on in a closure over the method's own frame, whose caller then
// names freed memory for the collector to meet (its issue 7711; ARCHITECTURE.md). A piece that
// only calls methods (`~pilot = FrictionPilot(...)`) is such a function, so each is compiled with
// one closure over a variable of its own, declared before the piece, or beside the piece's own
// declarations after a region's "(". Its frame is then the collector's, as any function's that
// makes a closure; its value and what it does are the same.
compileKeepingFrame = { |piece|
	var keep = "var kfKeptFrame = { kfKeptFrame };", lines = piece.split($\n);
	var first = lines.detectIndex { |line| headOf.(line).notEmpty }, next;
	next = first !? { lines.drop(first + 1).detectIndex { |line| headOf.(line).notEmpty } !? { |i| first + 1 + i } };
	if(next.notNil and: { headOf.(lines[first]) == "(" and: { "^var\\b".matchRegexp(headOf.(lines[next])) } }) {
		lines = lines.insert(first + 1, keep)
	} {
		lines = lines.insert(0, keep)
	};
	lines.join($\n).compile
};
// Each piece runs in a Routine of its own, as the IDE runs each at the top level, on a stack that
// starts empty. In SuperCollider 3.13 a non-local return (how try catches an error, how ^ leaves a
// block) leaves the arguments pending in the frames it unwinds on the thread's stack: in one Routine
// for the whole run they would pile up past its fixed-size stack, into the heap (ARCHITECTURE.md,
// sclang 3.13's stack, caught errors and its collector). The piece's environment
// (a ProxySpace pushed) carries on, as the IDE's does. Returns (threw:, value:, stack:): stack is
// the slots on the piece's stack at its end; a piece that threw nothing and leaves more than an
// empty one (pieceStack) is reported (KF-HELP-STACK-LEFT): its code piles them up in a long Routine.
// (Seen: FrictionCheck's example catching three refusals left 4 slots.)
runPiece = { |fn|
	var value, threw = false, stack, environment, routine, ended = Condition(false);
	routine = Routine {
		// The value is kept before it is posted: with "-> " ++ fn.value inside the try,
		// an error caught within the piece left 1.0 in place of the pending "-> ".
		try { value = fn.value } { |error| error.reportError; threw = true };
		environment = currentEnvironment;
		ended.test = true;
		ended.signal;
		\kfPieceEnd.yield;  // suspended (AppClock does not call it again), its stack is there to read
	};
	routine.play(AppClock);
	// Waiting on a Condition, the runner is on no clock's queue: a piece's Cmd-. (CmdPeriod.run)
	// clears the queues, and would have dropped a runner waiting there.
	ended.wait;
	stack = routine.instVarAt(\stack).size;
	routine.stop;
	currentEnvironment = environment;
	(threw: threw, value: value, stack: stack)
};
serverAlive = { s.pid.notNil and: { s.pid.pidRunning } };
restart = {
	"KF-HELP-SERVER-DIED\n".post;
	s.quit;
	// SC 3.13's boot waits 1 s for the old process's exit (Server:prWaitForPidRelease) and then
	// boots nothing, silently: wait for it (its pid is nil once sclang has seen it exit).
	10.do { if(s.pid.notNil) { 0.5.wait } };
	s.bootSync;
	"KF-SCSYNTH-PID %%\n".postf(s.pid);
};
// A boot is finished once ServerTree has run after it.
ServerBoot.add({ treePending = true }, s);
ServerTree.add({ treePending = false }, s);
// The routines waiting on the clocks fork and Routine.play use (TempoClock.default, SystemClock),
// and on AppClock those a piece's code made or s.waitForBoot's body: with the server running,
// ServerStatusWatcher runs that body in a Routine on AppClock, which a person waits for as for a
// fork (FrictionPilot's first block sets ~pilot so, and the next uses it). A class's own routine
// there (a study session's run, which the next block may abort) is not waited for.
routinesQueued = {
	var found = IdentitySet.new, appClockQueue = AppClock.classVars[0].queue.prInternalArray;  // its Scheduler
	var madeHere = { |routine|
		var def = routine.instVarAt(\func).tryPerform(\def);
		// The outermost definition: a Method (a class's code) or the interpreted piece's.
		while { def.notNil and: { def.isKindOf(Method).not } and: { def.context.notNil } } { def = def.context };
		def.isKindOf(Method).not or: { def.ownerClass == ServerStatusWatcher }
	};
	[TempoClock.default.queue, thisProcess.prSchedulerQueue, appClockQueue].do { |queue|
		if(queue.size > 1) { forBy(1, queue.size - 1, 3) { |i|
			var item = queue[i + 1];
			if(item.isKindOf(Routine) and: { queue !== appClockQueue or: { madeHere.(item) } }) { found.add(item) }
		} }
	};
	found
};
// After a piece, as a person waits before the next one: a pause (noting the routines the piece
// started), the boot if one is under way, then those routines' ends (a routine waiting on a
// Condition is off the clocks but not done: its state is kept, 6 when done).
waitLikeAPerson = { |known, path, b, value|
	var started = IdentitySet.new, until = Main.elapsedTime + %(piece_pause)f, note, waited = 0;
	// The Routine a piece returns (fork's): waited for even when it waits off the clocks' queues (on a
	// Condition: a report's Python), where the queues never show it.
	if(value.isKindOf(Routine) and: { known.includes(value).not }) { started.add(value) };
	note = { routinesQueued.().do { |r| if(known.includes(r).not) { started.add(r) } } };
	while { Main.elapsedTime < until } { note.(); 0.05.wait };
	while { (s.serverRunning.not or: { treePending }) and: { waited < %(boot_wait)f } } {
		0.1.wait; waited = waited + 0.1
	};
	// (Reported once: a boot that stopped before ServerTree is not waited for again.)
	if(waited >= %(boot_wait)f) { "KF-HELP-BOOT-TIMEOUT %% %%\n".postf(path, b); treePending = false };
	if(waited > 0 and: { s.serverRunning }) { s.sync };
	waited = 0;
	while { note.(); started.any { |r| r.state != 6 } and: { waited < %(fork_wait)f } } {
		0.05.wait; waited = waited + 0.05
	};
	started.do { |r| if(r.state != 6) { known.add(r) } };
};
hasDefaultGroup = {
	var seen = false, reply = OSCFunc({ seen = true }, '/n_info', s.addr, argTemplate: [1]);
	s.sendMsg('/n_query', 1);
	s.sync;
	reply.free;
	seen
};
// The nodes on the server but the root and the default groups (one per client), as [id, defName or \group].
nodesBesidesDefault = {
	var nodes = List.new, reply;
	// The reply comes before /synced: once synced it is in (or lost: then no node is reported).
	reply = OSCFunc({ |msg|
		var i = 2, walk;
		walk = {
			var id = msg[i], children = msg[i + 1];
			i = i + 2;
			if(children < 0) { nodes.add([id, msg[i]]); i = i + 1 } {
				nodes.add([id, \group]);
				children.do { walk.() };
			}
		};
		walk.();
	}, '/g_queryTree.reply', s.addr).oneShot;
	s.sendMsg('/g_queryTree', 0, 0);
	s.sync;
	reply.free;
	nodes.reject { |n| n[0] == 0 or: { n[1] == \kfHelpMeter } or: { s.defaultGroups.any { |g| g.nodeID == n[0] } } }
};

// What the speakers get (outputs 0 and 1), 20 times a second: what a listener hears (the RMS above
// 20 Hz over about 25 ms) and the largest sample over about the last 50 ms, a DC included. At the
// root node's tail, started again after every boot, Cmd-. and freeAll (ServerTree).
startMeter = {
	var def = SynthDef(\kfHelpMeter, {
		var in = In.ar(0, 2), trig = Impulse.kr(20);
		var heard = A2K.kr(HPF.ar(HPF.ar(in, 20), 20).squared.lag(0.025).sqrt);
		var peak = A2K.kr(LagUD.ar(in.abs, 0, 0.05));
		// A jump (a step between two samples) is a change far larger than the changes on either
		// side of it; a kink (the puck stopping or starting, a zoom doubling the rate of reading)
		// is not: its change is one of its neighbours'. The step above the larger neighbour,
		// against the larger neighbour, both held 0.2 s (60 dB).
		var change = (in - Delay1.ar(in)).abs, centre = Delay1.ar(change), sides = max(change, Delay2.ar(change));
		var heldStep = A2K.kr(LagUD.ar((centre - sides).max(0), 0, 0.2)), heldSides = A2K.kr(LagUD.ar(sides, 0, 0.2));
		var jump = (heldStep / heldSides.max(1e-12)) * (heldSides > 1e-7);
		SendReply.kr(trig, '/kfHelpMeter', [heard.reduce(\max), peak.reduce(\max), jump.reduce(\max)]);
	}), synth = Synth.basicNew(\kfHelpMeter, s);
	s.sendMsg('/d_recv', def.asBytes, synth.newMsg(RootNode(s), [], \addToTail));
};
OSCFunc({ |msg| meterLevels.add([Main.elapsedTime, msg[3], msg[4], msg[5]]) }, '/kfHelpMeter', s.addr).permanent = true;
if(%(meter)s) {
	ServerTree.add(startMeter, s);
	if(s.serverRunning) { startMeter.() };
};
// The levels since a piece started at t (the readings sent before it are in: s.sync at its
// start): the loudest heard from t + 0.1 s (before, what the piece before played still sounds on
// the meter: its 25 ms lag is 60 dB), the largest sample in the last 0.15 s (a sound freed is
// under -80 dBFS on the meter 70 ms later: a 50 ms release), and the largest jump from t + 0.5 s.
// A sound the piece starts or stops is a step (a pattern's first note s.latency, 0.2 s, after
// it), held until it falls under half the sound's own change per sample: a 0.1 step over a
// 0.0016 one (the LiveCoding guide's Pmono) in 0.14 s at 60 dB per 0.2 s. -1: no
// reading in the time (a peak or a jump with nothing to judge).
meterAtEnd = { meterLevels.select { |l| l[0] >= (Main.elapsedTime - 0.15) } };
levelsSince = { |t|
	var after = meterLevels.select { |l| l[0] >= (t + 0.1) };
	[after.collect(_[1]).maxItem ? 0, meterAtEnd.().collect(_[2]).maxItem ? -1,
		meterLevels.select { |l| l[0] >= (t + 0.5) }.collect(_[3]).maxItem ? -1]
};

// The force slot 0 commands (its status' lastForceN), 20 times a second, while a piece that says
// what force it commands runs: [readings as [time, N], the polling Routine].
pollForce = {
	var forces = List.new, routine = Routine {
		loop {
			FrictionDevice.at(s, 0) !? { |d|
				if(d.isOpen) { d.statusValues { |v| forces.add([Main.elapsedTime, v[\lastForceN]]) } }
			};
			0.05.wait
		}
	}.play(SystemClock);
	[forces, routine]
};
// The force readings of a piece started at t: from 0.1 s after it (before, the piece before's).
forcesSince = { |polled, t| polled[0].select { |f| f[0] >= (t + 0.1) }.collect(_[1]) };

// Waits (READINGS_WAIT_MAX_S at most) until a piece started at t has what judges it.
waitForReadings = { |t, polled|
	var waited = 0, missing = {
		(%(meter)s and: { s.serverRunning } and: { meterAtEnd.().isEmpty })
		or: { polled.notNil and: { forcesSince.(polled, t).size < %(force_readings)d } }
	};
	while { missing.() and: { waited < %(readings_wait)f } } { 0.05.wait; waited = waited + 0.05 };
	if(waited > 0) {
		"KF-HELP-READINGS-WAITED %% s meter %% force %%\n".postf(waited, meterLevels.size, polled !? { polled[0].size })
	};
};
// A piece that claims sound not yet heard is listened to, and one that claims a force not yet
// reached is polled, until `met` holds (CLAIM_WAIT_MAX_S at most), as a person listens or feels a
// moment longer for a puck that stands still. Posts how long it waited, as KF-HELP-<tag>.
waitForClaim = { |met, tag|
	var waited = 0;
	while { s.serverRunning and: { met.().not } and: { waited < %(claim_wait)f } } {
		0.05.wait; waited = waited + 0.05
	};
	if(waited > 0) { "KF-HELP-%% %% s\n".postf(tag, waited) };
};

"KF-HELP-TEMPDIR %%\n".postf(Platform.defaultTempDir);
pieceStack = runPiece.({ nil })[\stack];
files.do { |path, f|
	var doc = SCDoc.parseFileFull(path), blocks, known = routinesQueued.(), fileStart = Main.elapsedTime;
	if(doc.isNil) { "KF-HELP-PARSE-FAILED %%\n".postf(path) } {
		blocks = codeBlocks.(doc);
		"KF-HELP-FILE %% (%% blocks)\n".postf(path, blocks.size);
		blocks.do { |code, b|
			var pieces = piecesOf.(code), start = Main.elapsedTime;
			var lines = code.split($\n), first = lines.detect { |l| l.stripWhiteSpace.notEmpty and: { l.stripWhiteSpace != "(" } };
			// The block and its comments, for the test to read what they say it does.
			"KF-HELP-BLOCK %% %% %%\n".postf(path, b, (first ? "").stripWhiteSpace.keep(70));
			if(code.stripWhiteSpace.beginsWith("// needs ")) {
				"KF-HELP-SKIPPED %% %% (needs hardware)\n".postf(path, b);
				pieces = [];
			};
			pieces.do { |piece, p|
				var fn = compileKeepingFrame.(piece), run, pieceStart, polled;
				// The meter's readings sent before the piece are in before its time starts.
				if(%(meter)s and: { s.serverRunning }) { s.sync };
				pieceStart = Main.elapsedTime;
				if(piece.find("the force reaches").notNil or: { piece.find("the force stays").notNil }) {
					polled = pollForce.();
					known.add(polled[1]);  // not one of the piece's routines, to wait for
				};
				piece.split($\n).do { |line| line.find("//") !? { |at| "KF-HELP-COMMENT %% %%\n".postf(p, line.drop(at + 2)) } };
				"KF-HELP-PIECE %% %% %%\n".postf(path, b, p);
				if(fn.isNil) { "KF-HELP-COMPILE-FAILED %% %% %%\n".postf(path, b, p) } {
					run = runPiece.(fn);
					if(run[\threw]) { "KF-HELP-THROWN %% %% %%\n".postf(path, b, p) } {
						("-> " ++ run[\value].asString ++ "\n").post;
						// (A piece that catches errors itself leaves them there, as any caught error
						// does in SC 3.13: not ours to fix, and its Routine ends with the piece.)
						if(run[\stack] > pieceStack and: { piece.find("try").isNil and: { piece.find("protect").isNil } }) {
							"KF-HELP-STACK-LEFT %% %% %% %% slots\n".postf(path, b, p, run[\stack] - pieceStack)
						};
					};
				};
				waitLikeAPerson.(known, path, b, run !? { run[\value] });
				// The last piece's time runs to the block's end.
				if(p == (pieces.size - 1)) { (%(block_time)f - (Main.elapsedTime - start)).max(0.2).wait };
				waitForReadings.(pieceStart, polled);
				if(%(meter)s and: { piece.find("sound on the outputs").notNil } and: { piece.find("no sound on the outputs").isNil }) {
					waitForClaim.({ levelsSince.(pieceStart)[0] > %(heard_above)f }, "LISTENED")
				};
				piece.findRegexp("the force reaches ([0-9.]+) N").at(1) !? { |claim|
					waitForClaim.({ (forcesSince.(polled, pieceStart).maxItem ? 0) >= claim[1].asFloat }, "FELT-FOR")
				};
				"KF-HELP-LEVELS %% %% %% %% %% %%\n".postf(path, b, p, *levelsSince.(pieceStart));
				polled !? {
					var forces = forcesSince.(polled, pieceStart);
					polled[1].stop;
					"KF-HELP-FORCE %% %% %% %% %% %%\n".postf(path, b, p, forces.size, forces.minItem, forces.maxItem);
				};
				// (In place: the meter's responder holds this List.)
				while { meterLevels.notEmpty and: { meterLevels[0][0] < (Main.elapsedTime - 1) } } { meterLevels.removeAt(0) };
			};
			"KF-HELP-BLOCK-END %% %%\n".postf(path, b);
			if(serverAlive.().not) { restart.() } {
				if(hasDefaultGroup.().not) { "KF-HELP-NO-DEFAULT-GROUP %% %%\n".postf(path, b) };
				if(%(free_each_block)s) { s.freeAll; s.sync };
			};
		};
		// A guide's last block is its clean-up: nothing of it may still run or post.
		if(guides[f] and: { serverAlive.() }) {
			"KF-HELP-CLEANED-UP %%\n".postf(path);
			%(cleanup_watch)f.wait;
			nodesBesidesDefault.().do { |n| "KF-HELP-LEFT-RUNNING %% %%\n".postf(path, n) };
		};
		s.freeAll;
		16.do { |i| s.sendMsg('/cmd', 'kfClose', i) };
		s.sync;
		Window.allWindows.do(_.close);
		0.2.wait;
		if(serverAlive.().not) { restart.() };
		"KF-HELP-FILE-DONE %% in %% s\n".postf(path, (Main.elapsedTime - fileStart).round(0.1));
	};
};
// The soak, after the guides in their interpreter: every threshold procedure run again and again in one
// Routine, as a study session runs them, its stack read after every run (a procedure that leaves slots
// on it would overflow it in a long session), then the heap walked by a full collection.
if(%(soak)s and: { guides.includes(true) }) {
	var levels = FrictionPsychometric.logLevels(0.01, 1, 30);
	[
		[\questPlus, { FrictionQuestPlus(levels, maxTrials: 40) }],
		[\constantStimuli, { |i| FrictionConstantStimuli(levels.copyRange(8, 22), 4, seed: i) }],
		[\staircase2down, { FrictionStaircase(0.3, 2, maxTrials: 60) }],
		[\staircase3down, { FrictionStaircase(0.3, 3, maxTrials: 60) }]
	].do { |named|
		var stacks = List.new, start = Main.elapsedTime, routine = Routine {
			(%(soak_runs)s[named[0]]).do { |i|
				FrictionObserver(0.1, 3.5, 0.02, seed: i).runProcedure(named[1].(i));
				\kfSoakRun.yield
			}
		};
		while { routine.next == \kfSoakRun } { stacks.add(routine.instVarAt(\stack).size) };
		"KF-HELP-SOAK %% runs %% stack %% to %% in %% s\n".postf(named[0], stacks.size, stacks.first, stacks.maxItem,
			(Main.elapsedTime - start).round(0.1));
		0.01.wait;
	};
	// The collector's own check of its heap: it prints what it finds wrong ("grey count off", a list's
	// "color wrong"), which FAILURES reads.
	this.gcSanity;
	"KF-HELP-GC-CHECKED\n".post;
};
"KF-HELP-ALL-DONE\n".post;
"""

FAILURES = [
    (re.compile(r"FAILURE IN SERVER"), "the server failed a command"),
    (re.compile(r"Node -?\d+ not found"), "a node that is not there"),
    (re.compile(r"^ERROR"), "sclang error"),
    (re.compile(r"\*\*\* ERROR"), "an error"),
    (re.compile(r"^KF-HELP-THROWN"), "a piece threw"),
    (re.compile(r"DoesNotUnderstand|^(PROTECTED )?CALL STACK"), "an sclang exception"),
    (re.compile(r"^KF-HELP-COMPILE-FAILED"), "a piece does not compile"),
    (re.compile(r"^KF-HELP-PARSE-FAILED"), "the help file does not parse"),
    (re.compile(r"^KF-HELP-SERVER-DIED"), "scsynth exited"),
    (re.compile(r"^KF-HELP-BOOT-TIMEOUT"), "the server did not finish booting"),
    (re.compile(r"^KF-HELP-NO-DEFAULT-GROUP"), "the server has no default group (node 1)"),
    (re.compile(r"grey count|color wrong|gcset wrong|next->prev != obj|grey obj on free list"),
     "sclang's heap is inconsistent (its collector's own check)"),
    (re.compile(r"^KF-HELP-STACK-LEFT"), "a piece left slots on its thread's stack (non-local returns through "
     "pending arguments: sclang 3.13 overflows a long Routine's stack into its heap)"),
    (re.compile(r"^KF-HELP-LEFT-RUNNING"), "a node left running after the guide's clean-up"),
    # A reboot's quit ends scsynth with 0; a server that died unasked is KF-HELP-SERVER-DIED.
    (re.compile(r"^Server '\w+' exited with exit code (?!0\.)"), "scsynth exited"),
    (re.compile(r"^(Segmentation fault|Aborted|terminate called)"), "a crash"),
    (re.compile(r"RT memory allocation failed"), "RT memory allocation failed"),
    # The plugin's commands post only their refusals as "<command>: <reason>"; kfListMice also
    # posts its count so, and kfOpenReplay a warning about the file it still plays.
    (re.compile(r"^kf\w+: (?!warning: |\w+: \d+ mice$)"), "a command refused by the server"),
]
# In a guide: a synth reading or writing a slot with no device, one its example did not free.
CLOSED_DEVICE = re.compile(r"no device is open")
NOTES = [re.compile(p) for p in (r"^WARNING", r"^KF-HELP-NOTE", r"no device is open", r"^kf\w+: ")]
COMMENT = re.compile(r"^KF-HELP-COMMENT (\d+) (.*)$")
# What a comment says the example does (the text after "//").
ANNOTATIONS = [
    ("->", re.compile(r"^\s*-> (.*?)\s*$")),
    ("posts", re.compile(r'\bposts "(.*)"')),
    ("fails with", re.compile(r'\bfails with "(.*)"')),
    ("writes", re.compile(r"\bwrites (\S+\.\w+(?: \([^)]*\))?)")),
    ("force reaches", re.compile(r"\bthe force reaches ([-+]?\d+(?:\.\d+)?) N\b")),
    ("force stays at", re.compile(r"\bthe force stays at ([-+]?\d+(?:\.\d+)?) N\b")),
    ("force stays between", re.compile(r"\bthe force stays between ([-+]?\d+(?:\.\d+)? and [-+]?\d+(?:\.\d+)?) N\b")),
    ("no jump", re.compile(r"\b(no jump) in the sound\b")),
    ("sound", re.compile(r"(?<!\bno )\b(sound) on the outputs\b")),
    ("silence", re.compile(r"\b(silence) on the outputs\b")),
]
# The outputs' levels (KF-HELP-LEVELS, the runner's meter on outputs 0 and 1): "sound on the
# outputs" is heard (RMS above 20 Hz) above -60 dBFS; "silence on the outputs" is every sample, a
# DC included, under -80 dBFS in the last 0.15 s. The meter read 0 exactly where nothing played;
# the quietest sound a guide claims (the Patterns guide's grating clicks) measured -43 dBFS, and
# a sound freed reads under 1e-6 after 0.1 s.
HEARD_ABOVE = 1e-3
SILENT_BELOW = 1e-4
# "no jump in the sound": a step d between two samples whose neighbours change by v reads
# (d - v) / d, against its neighbours (the held step above the larger one, over the larger one),
# so 0.5 is a step twice a sample's change around it (the broken example's 4 Hz pulse beside a
# 300 Hz sine: d = 0.1, v = 0.004, 0.96 in theory, 0.94 measured). A kink reads 0 (the broken
# example's 300 Hz triangle: 3e-6): where the puck stops or starts (the change goes to or from 0:
# near a hand's reversal a 125 Hz report of 1 count and then one of none) or a zoom doubles the
# rate of reading, the change equals one neighbour's. The LiveCoding guide's scrub, measured at 41
# moments of its hand's sweep, read 0.010 to 0.20, and 0.55 to 1 at all 41 with its zoom made to
# jump (keep: 0). (The second difference against the first, the meter before, read those kinks as
# about 1 and failed the scrub at 7 of 40 moments.) A smooth sound of frequency f reads
# (2 pi f / fs)^2 / 2 at most, the peak of its change: under 0.5 up to 7.6 kHz at 48 kHz; a noise
# reads about 1.
JUMP_BELOW = 0.5
OLD_MARKER = re.compile(r"^\s*(posts|expect error|writes):")
NUMBER = r"[-+]?\d+(?:\.\d+)?(?:[eE][-+]?\d+)?"


def help_files():
    """The help files this run takes: every one under HELP_DIR, or the selection (each must exist)."""
    files = sorted(HELP_DIR.rglob("*.schelp"))
    if not SELECTED:
        return files
    names = {f.relative_to(HELP_DIR).with_suffix("").as_posix(): f for f in files}
    missing = [name for name in SELECTED if name not in names]
    assert not missing, f"KF_HELP_FILES names help files that are not in {HELP_DIR}: {missing}"
    return sorted(names[name] for name in SELECTED)


def is_guide(path):
    """A guide (or overview): a file a user follows from top to bottom, not a class's reference."""
    return Path(path).parent.name != "Classes"


def guide_order(files):
    """The guides and overviews of `files` in the order a user meets them: each overview, then the
    guides in the order it links them, then the guides it does not link, sorted."""
    guides = sorted(f for f in files if is_guide(f))
    overviews = [f for f in guides if f.parent.name == "Overviews"]
    ordered = list(overviews)
    for overview in overviews:
        for name in LINK.findall(overview.read_text()):
            linked = [f for f in guides if f.relative_to(f.parent.parent).with_suffix("").as_posix() == name]
            ordered += [f for f in linked if f not in ordered]
    return ordered + [f for f in guides if f not in ordered]


class Example:
    """One code block: what its comments expect, what was posted while it and the rest of its
    file ran, and the failure lines posted while it ran."""

    def __init__(self, path, block, first_line):
        self.path, self.block, self.first_line = path, block, first_line
        self.expects = []  # (kind, text, piece)
        self.output = []
        self.failures = []  # (piece, what, line)
        self.levels = {}  # piece: (loudest heard, largest sample at its end, largest jump), the meter's
        self.forces = {}  # piece: (readings, least, most) of slot 0's commanded force (N)

    def __str__(self):
        return f"{self.path} block {self.block} ({self.first_line})"


def precision(number):
    """Half a unit of the last digit a number is written with: "0.56" -> 0.005, "1e-3" -> 0.0005."""
    decimals = len(number.split(".")[1].split("e")[0].split("E")[0]) if "." in number else 0
    exponent = int(re.split("[eE]", number)[1]) if re.search("[eE]", number) else 0
    return 0.5 * 10.0 ** (exponent - decimals)


def matcher(text, whole_line=False):
    """A function telling whether a posted line holds `text`, its numbers to the precision written."""
    parts = re.split(f"(?<![\\w.])({NUMBER})(?![\\d.])", text.strip())
    pattern, wanted = "", []
    for i, part in enumerate(parts):
        if i % 2:
            wanted.append((float(part), precision(part)))
            pattern += f"(?<![\\w.])({NUMBER})(?![\\d.])"
        else:
            pattern += r"\s+".join(re.escape(word) for word in part.split(" ")) if part.strip() else re.escape(part)
    regex = re.compile(f"^{pattern}$" if whole_line else pattern)

    def holds(line):
        for m in regex.finditer(line.strip()):
            if all(abs(float(got) - value) <= tolerance for got, (value, tolerance) in zip(m.groups(), wanted)):
                return True
        return False
    return holds


def check_written(text, temp_dir, since):
    """Why the file `text` names was not written as it says, or None."""
    m = re.fullmatch(r"(\S+)(?: \((.*)\))?", text.strip())
    # A "*" stands for a part the example makes up (a study's root: "kf-study-guide-" ++ 1e6.rand).
    candidates = Path(temp_dir).glob(m[1]) if "*" in m[1] else [Path(temp_dir) / m[1]]
    written = [path for path in candidates if path.is_file() and path.stat().st_mtime >= since]
    if not written:
        return f"{Path(temp_dir) / m[1]} was not written"
    path = max(written, key=lambda path: path.stat().st_mtime)
    for detail in (m[2] or "").split(", "):
        if not detail:
            continue
        data, rate = readers.read_wav(path)
        if c := re.fullmatch(r"(\d+) channels?", detail):
            if data.shape[1] != int(c[1]):
                return f"{path} has {data.shape[1]} channels, not {c[1]}"
        elif d := re.fullmatch(f"({NUMBER}) s", detail):
            if abs(len(data) / rate - float(d[1])) > 0.01:
                return f"{path} lasts {len(data) / rate:.4f} s, not {d[1]} s"
        else:
            return f"cannot check '{detail}' of {path}"
    return None


# A run's hang guard: sclang is killed after this, so that the report says where it stood (under
# ctest's TIMEOUT of 600 s, tests/realtime/CMakeLists.txt, which would kill the whole test). Not a
# bound on its time: the guides' run, the longest, took 220 s of an idle fresh clone (at 23cb9a2)
# and passed 240 s beside a second test command (fresh clones 65 and 66, killed in the Study guide);
# 540 s is 2.5 times the idle run.
RUN_TIMEOUT_S = 540


def run_examples(files, jack, timeout=RUN_TIMEOUT_S, after=None, booted=None, soak=False):
    """Runs every example of `files`, in this order, on one server booted against `jack`, once the
    Event `after` (if any) is set; sets `booted` when its server is up. Returns (run, examples,
    problems, notes): problems are the failures and unmet expectations, each naming its example.
    soak: the threshold procedures' soak after the guides (if `files` has guides)."""
    if after is not None:
        after.wait()
    since = time.time()
    code = RUNNER % dict(files=", ".join(sclang.sc_string(f) for f in files),
                         guides=", ".join(str(is_guide(f)).lower() for f in files),
                         piece_pause=PIECE_PAUSE_S, block_time=BLOCK_TIME_S, fork_wait=FORK_WAIT_MAX_S,
                         boot_wait=BOOT_WAIT_MAX_S, cleanup_watch=CLEANUP_WATCH_S,
                         readings_wait=READINGS_WAIT_MAX_S, force_readings=FORCE_READINGS,
                         heard_above=HEARD_ABOVE, claim_wait=CLAIM_WAIT_MAX_S,
                         free_each_block=str(FREE_EACH_BLOCK).lower(), soak=str(soak).lower(), meter=str(METER).lower(),
                         soak_runs="(" + ", ".join(f"{k}: {v}" for k, v in SOAK_RUNS.items()) + ")")
    run = sclang.run_with_server(code, jack, name="help", timeout=timeout, booted=booted,
                                 # The study's examples: the participant's pair and the experimenter's.
                                 server_options={"numOutputBusChannels": 4})
    examples, in_file, current, notes, problems = [], [], None, [], []
    where, temp_dir, finished, in_stack = "(before the first example)", "/tmp", False, False
    for line in run.output.splitlines():
        # An error dump's call stack prints the runner's variables, the examples' code among them:
        # not output, and not failures of their own (the dump's ERROR line is). It ends with a
        # "^^ ..." line, or at the runner's next line.
        if in_stack:
            in_stack = not line.startswith(("^^", "KF-HELP-"))
            if in_stack:
                continue
        in_stack = bool(re.match(r"(PROTECTED )?CALL STACK", line))
        if line.startswith("KF-HELP-ALL-DONE"):
            finished = True
            break  # then the harness's own server quit
        if line.startswith("KF-HELP-TEMPDIR "):
            temp_dir = line.split(" ", 1)[1]
            continue
        if line.startswith("KF-HELP-BLOCK "):
            path, block, first_line = (line.split(" ", 3) + [""])[1:4]
            current = Example(path, int(block), first_line)
            examples.append(current)
            in_file.append(current)
            where = "piece -"
            continue
        if m := COMMENT.match(line):
            piece, comment = int(m[1]), m[2]
            if OLD_MARKER.match(comment):
                problems.append(f"{current}: a test marker of an earlier version, not read: //{comment} "
                                "(write // posts \"...\", // fails with \"...\", // writes <file>)")
            for kind, annotation in ANNOTATIONS:
                if found := annotation.search(comment):
                    current.expects.append((kind, found[1], piece))
            continue
        if line.startswith("KF-HELP-LEVELS ") and current is not None:
            current.levels[int(line.split()[-4])] = tuple(float(v) for v in line.split()[-3:])
        if line.startswith("KF-HELP-FORCE ") and current is not None:
            count, least, most = line.split()[-3:]
            current.forces[int(line.split()[-4])] = (int(count), float(least), float(most)) if int(count) else (0, 0, 0)
        if line.startswith("KF-HELP-PIECE "):
            where = "piece " + line.split()[-1]
        if line.startswith("KF-HELP-CLEANED-UP "):
            where = "after the clean-up"
        if line.startswith("KF-HELP-FILE-DONE "):
            in_file = []
        if not line.startswith("KF-HELP-"):
            for example in in_file:
                example.output.append(line)
        if current is not None and is_guide(current.path) and CLOSED_DEVICE.search(line):
            current.failures.append((where, "a synth reads or writes a slot with no device (not freed with it?)", line))
            continue
        for pattern, what in FAILURES:
            if pattern.search(line):
                if current is None:
                    problems.append(f"{where}: {what}: {line}")
                else:
                    current.failures.append((where, what, line))
                break
        else:
            if any(p.search(line) for p in NOTES):
                notes.append(f"{current or where}: {line}")
    if not finished or not run.ok:
        why = "timed out" if "timed out" in run.output or "KF-SCRIPT-TIMEOUT" in run.output else \
            f"exited with {run.returncode}"
        problems.append(f"the run {why} while running {current} {where}; log {run.log_path}")

    for example in examples:
        expected_errors = [text for kind, text, _ in example.expects if kind == "fails with"]
        seen, reported = set(), set()
        for piece, what, line in example.failures:
            shown = [text for text in expected_errors if text in line]
            seen.update(shown)
            if not shown and (piece, what) not in reported:  # one line of each kind a piece: no call stacks
                reported.add((piece, what))
                problems.append(f"{example} {piece}: {what}: {line}")
        for kind, text, piece in example.expects:
            if kind in METER_CLAIMS and not METER:
                continue
            if kind == "fails with":
                ok = text in seen
            elif kind == "->":
                ok = any(map(matcher("-> " + text, whole_line=True), example.output))
            elif kind == "posts":
                ok = any(map(matcher(text), example.output))
            elif kind.startswith("force"):
                # Slot 0's commanded force over the piece's time (from 0.1 s after it starts), to the
                # precision the number is written with.
                count, least, most = example.forces.get(piece, (0, 0, 0))
                low, high = text.split(" and ") if kind == "force stays between" else (text, text)
                if kind == "force reaches":
                    ok = most >= float(text) - precision(text)
                else:
                    ok = float(low) - precision(low) <= least and most <= float(high) + precision(high)
                ok = ok and count > 0
                if not ok:
                    problems.append(f"{example} piece {piece}: // the {kind} {text} N: slot 0 commanded "
                                    f"{least:g} to {most:g} N ({count} readings)")
                continue
            elif kind == "no jump":
                # The largest step against the changes beside it over the piece's time, to the
                # block's end for the last piece: under JUMP_BELOW, and a sound to judge.
                heard, _, jump = example.levels.get(piece, (0.0, 0.0, -1.0))
                if not (heard > HEARD_ABOVE and 0 <= jump < JUMP_BELOW):
                    problems.append(f"{example} piece {piece}: // no jump in the sound: a step between samples "
                                    f"reached {jump:.2g} of the changes beside it (a jump: about 1), heard {heard:.2g}")
                continue
            elif kind in ("sound", "silence"):
                # Sound: heard from the piece on, until the block's end (a pilot sounds once its puck
                # reaches the fragment, after the next line maybe); silence: at the end of the
                # piece's own time, before the next piece.
                later = [levels for p, levels in example.levels.items() if p >= piece]
                heard = max((h for h, _, _ in later), default=0.0)
                last_peak = example.levels.get(piece, (0.0, -1.0, -1.0))[1]  # -1: no reading
                if not (heard > HEARD_ABOVE if kind == "sound" else 0 <= last_peak < SILENT_BELOW):
                    problems.append(f"{example} piece {piece}: // {kind} on the outputs: the loudest heard {heard:.2g}, "
                                    f"the largest sample at its end {last_peak:.2g}")
                continue
            else:
                why = check_written(text, temp_dir, since)
                if why:
                    problems.append(f"{example}: // writes {text}: {why}")
                continue
            if not ok:
                # What came instead: lines holding the text before its first number, or its values.
                head = re.split(NUMBER, text)[0].strip() if kind == "posts" else ""
                came = [line for line in example.output if (line.startswith("-> ") if not head else head in line)]
                said = f"-> {text}" if kind == "->" else f'{kind} "{text}"'
                problems.append(f"{example}: // {said}: not posted (posted: {came[:4]})")
    if not problems:
        remove_numbered_folders(files, temp_dir, since)
    return run, examples, problems, notes


def remove_numbered_folders(files, temp_dir, since):
    """The folders the examples of `files` made in Platform.defaultTempDir under a prefix and a
    random number (a study's root: "kf-study-guide-" ++ 1e6.rand): each run made new ones, 3 MB
    each, where the files of fixed names are overwritten by the next run. Kept when a run failed."""
    prefixes = [re.escape(name) for f in files for name in temp_names(f) if name.endswith("-")]
    if not prefixes:
        return
    numbered = re.compile(f"({'|'.join(prefixes)})[0-9]+")
    for folder in Path(temp_dir).iterdir():
        if numbered.fullmatch(folder.name) and folder.is_dir() and folder.stat().st_mtime >= since:
            shutil.rmtree(folder, ignore_errors=True)


def temp_names(path):
    """The files in Platform.defaultTempDir the examples of `path` that run name (not those that
    need hardware)."""
    blocks = [b for b in CODE_BLOCK.findall(path.read_text()) if not b.strip().startswith("// needs ")]
    return set(name for b in blocks for name in TEMP_NAME.findall(b))


def blocks_in(path):
    return len(CODE_BLOCK.findall(path.read_text()))


def shards_of(files, count):
    """`files` in lists to run side by side: the guides in one, in guide_order; the class help
    files in count - 1 more, each in the sorted order. Files naming the same file in
    Platform.defaultTempDir (one writes what another reads, or both write it) stay in one list, in
    order; the lists are balanced by their number of code blocks."""
    guides = guide_order(files)
    groups = []  # [(temp names, files)]
    for f in [f for f in files if not is_guide(f)]:
        names = temp_names(f)
        joined = [g for g in groups if g[0] & names]
        merged = (names.union(*(g[0] for g in joined)), [x for g in joined for x in g[1]] + [f])
        groups = [g for g in groups if g not in joined] + [merged]
    guide_names = set().union(*map(temp_names, guides))
    shards = [[] for _ in range(count - 1)]
    weight = [0] * (count - 1)
    for names, group in sorted(groups, key=lambda g: -sum(map(blocks_in, g[1]))):
        if names & guide_names:
            guides += group  # it shares a temp file with a guide: after them, on their server
            continue
        i = weight.index(min(weight))
        shards[i] += group
        weight[i] += sum(map(blocks_in, group))
    return [shard for shard in [guides] + [sorted(shard) for shard in shards] if shard]


def test_help_shards_keep_files_sharing_a_temp_file_together():
    files = sorted(HELP_DIR.rglob("*.schelp"))
    shards = shards_of(files, SHARDS)
    assert sorted(f for shard in shards for f in shard) == files
    owner = {}
    for i, shard in enumerate(shards):
        for f in shard:
            for name in temp_names(f):
                assert owner.setdefault(name, i) == i, f"{name} is used by files in two shards"
    guides = [f for f in files if is_guide(f)]
    assert guides and shards[0][:len(guides)] == guide_order(files), "the guides run first, in one session"
    assert shards[0][0].parent.name == "Overviews", "a user starts at the overview"


@pytest.mark.parametrize("part", ["guides", "classes"])
def test_every_help_example_runs_on_a_realtime_server(part):
    """part: the guides' server (the overview and the guides, then the soak), or the class help
    files' servers. Two ctest entries (tests/realtime/CMakeLists.txt), so that each holds its lane
    as long as its servers play: the guides' run is the longest of the three shards (114 s here,
    the two others 58 and 79 s), and the three as one test held two lanes until it ended."""
    files = help_files()
    assert files, "no help files"
    shards = [shard for shard in shards_of(files, SHARDS) if is_guide(shard[0]) == (part == "guides")]
    if not shards:
        pytest.skip(f"no {part} among the help files")
    with ExitStack() as stack:
        # The examples write where a user's would, in /tmp (Platform.defaultTempDir): a second test
        # command's run of the same part replayed a session file this one was writing (fresh clones
        # 81 and 82: the NoHardware guide's replay silent, the Pilot guide's "line longer than 4096
        # characters"). Within one command ctest orders the two builds' runs (RESOURCE_LOCK).
        stack.enter_context(procs.machine_lock(f"kf-help-temp-files-{part}"))
        # Run as the other realtime tests run (conftest.performer_jack).
        jacks = [stack.enter_context(performer_jack()) for _ in shards]
        # The servers boot one after another: scsynths opening their JACK clients at the same
        # moment failed to ("Cannot open SuperCollider client") under the sanitizers.
        booted = [threading.Event() for _ in shards]
        with ThreadPoolExecutor(len(shards)) as pool:
            results = list(pool.map(lambda i: run_examples(shards[i], jacks[i], after=booted[i - 1] if i else None,
                                                           booted=booted[i], soak=SOAK), range(len(shards))))
        jacks_alive = all(jack.alive() for jack in jacks)

    problems = [p for _, _, shard_problems, _ in results for p in shard_problems]
    notes = [n for _, _, _, shard_notes in results for n in shard_notes]
    examples = [e for _, shard_examples, _, _ in results for e in shard_examples]
    summary = paths.work_dir() / "help-examples-summary.txt"
    summary.write_text("\n".join(["PROBLEMS"] + problems + ["", "NOTES"] + notes) + "\n")
    print("\n".join(f"log {run.log_path}" for run, *_ in results) + f"\nsummary {summary}")
    print("\n".join(notes))
    assert jacks_alive, "jackd died during the examples"
    for shard, (run, *_) in zip(shards, results):
        for f in shard:
            assert f"KF-HELP-FILE-DONE {f}" in run.output, f"{f} did not run, log {run.log_path}"
    assert not problems, "help examples with problems:\n" + "\n".join(problems)
    # Every part reads at least 10, the sanitized run's selection too (13 in its guides, 12 in its
    # class files at d93f5e2).
    assert sum(len(e.expects) for e in examples) >= 10, "the help's output annotations were not read"
    if SOAK and part == "guides":
        guides_run = results[0][0]
        soaks = re.findall(r"^KF-HELP-SOAK (\w+) runs (\d+) stack (\d+) to (\d+)", guides_run.output, re.M)
        assert {name: int(runs) for name, runs, *_ in soaks} == SOAK_RUNS, f"the soak did not run whole: {soaks}"
        for name, _, first, most in soaks:
            assert first == most, f"{name} left {int(most) - int(first)} slots on its Routine's stack over the soak"
        assert "KF-HELP-GC-CHECKED" in guides_run.output, "the heap was not checked after the soak"


# Broken examples, one way each, and good blocks: every broken one must be reported, the good
# ones not. One server run for all: a class's help and a guide (its stricter rules, a reboot and a
# fork longer than the pause between pieces, which a person waits for: with FORK_WAIT_MAX_S or
# BOOT_WAIT_MAX_S at 0 the good blocks 0 and 1 of the guide are reported). (Node numbers far above
# those sclang allocates.)
BROKEN_HELP = """title:: BrokenExamples
summary:: Examples the help-example test must report
categories:: KineticFriction

description::

code::
s.sendMsg("/n_set", 99999, \\freq, 1);
::

code::
Error("a broken example").throw;
nil.kfNoSuchMethod;
::

code::
(1 + 1).postln;  // posts "3"
0.5 + 0.25;  // -> 0.9
1 + 1;  // writes kf-help-never-written.wav
1 + 1;  // writes kf-help-never-*/written.csv
::

code::
// fails with "Node 99997 not found"
s.sendMsg("/n_free", 99996);
::

code::
// this fails with "Node 99998 not found"
s.sendMsg("/n_free", 99998);
(1 + 1).postln;  // this posts "2"
0.5 + 0.25;  // -> 0.75
::

code::
(1 + 1).postln;  // posts: 2
::

code::
// a catch the runner cannot see in the piece, as a class's method would hide it
{ [1, 2].collect { |x| Error("caught, in the middle of collect").throw } }.perform(("tr" ++ "y").asSymbol, { 0 });
::

code::
// A piece that only calls methods keeps its frame while a method's closure names it (compileKeepingFrame)
~kfPieceDef = thisFunctionDef; ~kfEscaped = { 42 }.inEnvir; nil
~kfEscaped.slotAt(1).slotAt(1).slotAt(0) === ~kfPieceDef  // -> true
::

code::
s.sendMsg("/n_free", 1);
::
"""
BROKEN_GUIDE = """title:: BrokenGuide
summary:: A guide the help-example test must report
categories:: KineticFriction

description::

code::
(
~kfDone = false;
fork { 1.0.wait; ~kfDone = true };
)
"waited: %".format(~kfDone).postln;  // posts "waited: true"
(
~kfBooted = false;
s.waitForBoot { 1.0.wait; ~kfBooted = true };  // the server runs: its body runs on AppClock
)
"booted: %".format(~kfBooted).postln;  // posts "booted: true"
::

code::
s.reboot;
"running: %".format(s.serverRunning).postln;  // posts "running: true"
::

code::
~kfDc = { DC.ar(0.2) ! 2 }.play;  // silence on the outputs (but a DC is no silence)
::

code::
// sound on the outputs: a sine instead of the DC
(~kfDc.free; ~kfSine = { SinOsc.ar(440, 0, 0.1) ! 2 }.play;)
::

code::
~kfSine.free;  // silence on the outputs
::

code::
1 + 1;  // sound on the outputs (but nothing plays)
::

code::
~kfSine = { SinOsc.ar(440, 0, 0.1) ! 2 }.play;  // sound on the outputs
~kfSine.free;  // sound on the outputs (but the piece before played it)
::

code::
~kfSmooth = { LFTri.ar(300, 0, 0.1) ! 2 }.play;  // no jump in the sound (a triangle's kinks are none)
::

code::
(~kfSmooth.free; ~kfJumpy = { (SinOsc.ar(300) + LFPulse.ar(4)) * 0.1 ! 2 }.play;)  // no jump in the sound (but a pulse)
::

code::
~kfJumpy.free;  // no sound on the outputs from here (a comment that claims no sound)
::

code::
(
fork {
	~kfForce = FrictionDevice.sim(s, 0, replace: true);
	s.sync;
	~kfPush = { FrictionOut.ar(0, DC.ar(0.3)); Silent.ar }.play;
};
)
// the force reaches 0.3 N (sclang then stands still through the piece's pause, as beside hogs)
AppClock.sched(0.05, { var t = Main.elapsedTime; while { Main.elapsedTime - t < 0.5 } { }; nil });
// the force stays at 0.5 N (but it is 0.3 N)
2 + 2;
// the force stays between 0.14 and 0.2 N (but it is 0.3 N)
3 + 3;
(~kfPush.free; ~kfForce.close;)
::

code::
(
fork {
	~kfDev = FrictionDevice.sim(s, 9, replace: true);
	~kfReader = { FrictionMouseIn.kr(9)[0]; Silent.ar }.play;
};
)
::

code::
~kfDev.close;
::
"""
# (file, block, what its report says)
BROKEN = [("BrokenExamples", 0, "FAILURE IN SERVER /n_set Node 99999 not found"),
          ("BrokenExamples", 1, "ERROR: a broken example"),
          ("BrokenExamples", 1, "Message 'kfNoSuchMethod' not understood"),
          ("BrokenExamples", 2, '// posts "3": not posted'), ("BrokenExamples", 2, "// -> 0.9: not posted"),
          ("BrokenExamples", 2, "kf-help-never-written.wav was not written"),
          ("BrokenExamples", 2, "kf-help-never-*/written.csv was not written"),
          ("BrokenExamples", 3, "FAILURE IN SERVER /n_free Node 99996 not found"),
          ("BrokenExamples", 3, '// fails with "Node 99997 not found": not posted'),
          ("BrokenExamples", 5, "a test marker of an earlier version, not read: // posts: 2"),
          ("BrokenExamples", 6, "left slots on its thread's stack"),
          ("BrokenExamples", 8, "the server has no default group"),
          # (0.3 N commanded, or the floor's 0.14 N in a frame after a watchdog trip on a busy machine)
          ("BrokenGuide", 10, "piece 2: // the force stays at 0.5 N: slot 0 commanded"),
          ("BrokenGuide", 10, "piece 3: // the force stays between 0.14 and 0.2 N: slot 0 commanded"),
          ("BrokenGuide", 12, "a slot with no device"), ("BrokenGuide", 12, "a node left running")]
# The meter's claims (the release pass only: METER).
BROKEN_METER = [("BrokenGuide", 2, "// silence on the outputs: the loudest heard"),
                ("BrokenGuide", 5, "piece 0: // sound on the outputs: the loudest heard"),
                ("BrokenGuide", 6, "piece 1: // sound on the outputs: the loudest heard"),
                ("BrokenGuide", 8, "piece 0: // no jump in the sound: a step between samples")]
GOOD = [("BrokenExamples", 4), ("BrokenExamples", 7)] + [("BrokenGuide", b) for b in (0, 1, 3, 4, 7, 9, 11)]


def test_broken_examples_are_reported(tmp_path):
    help_files = [tmp_path / "HelpSource" / "Classes" / "BrokenExamples.schelp",
                  tmp_path / "HelpSource" / "Guides" / "BrokenGuide.schelp"]
    for path, text in zip(help_files, [BROKEN_HELP, BROKEN_GUIDE]):
        path.parent.mkdir(parents=True)
        path.write_text(text)
    with JackServer() as jack:
        run, examples, problems, notes = run_examples(help_files, jack, timeout=120)
    print("\n".join(problems))
    assert run.ok and [(Path(e.path).stem, e.block) for e in examples] == \
        [("BrokenExamples", b) for b in range(9)] + [("BrokenGuide", b) for b in range(13)], run.output[-3000:]
    named = {path.stem: path for path in help_files}
    for name, block, what in BROKEN + (BROKEN_METER if METER else []):
        assert any(p.startswith(f"{named[name]} block {block} ") and what in p for p in problems), \
            f"broken block {block} of {name} not reported as '{what}':\n" + "\n".join(problems)
    for name, block in GOOD:
        assert not [p for p in problems if p.startswith(f"{named[name]} block {block} ")], problems
    # Block 6's first piece sounds as it says, block 10's second commands the force it says: only
    # the piece after each is reported. (Block 10's second stalls sclang through its pause: judged
    # on no reading, 0 of them, without waitForReadings.)
    for block, piece in ((6, 0), (10, 1)):
        assert not [p for p in problems if p.startswith(f"{named['BrokenGuide']} block {block} ") and
                    f"piece {piece}" in p], problems
