// The answers to FrictionDevice's asynchronous commands (the plugin's CommandRunner), both node
// replies to the clients registered with /notify (sclang is by default): /kfDone when the
// command succeeded and /kfFail when the server refused it, whatever was wrong; each from node
// 0, reply ID the slot (-1 when the device argument itself was wrong, or the command has none),
// then character codes: the command's name (/kfDone) or the reason, which starts with it
// (/kfFail). Nothing only when the server is gone, so a timeout. The server's /done cmdName
// carries no slot (a plugin's /done cannot: CommandRunner.hpp), so it is not used here: two
// commands of one name in flight are matched by (command, slot), not by the order they answer.
// One pair of responders per server; the commands awaiting an answer, by server.
FrictionAnswers {
	classvar pending, responders, <>timeout = 5;

	*initClass {
		pending = IdentityDictionary.new;
		responders = IdentityDictionary.new;
	}

	// Sends msg (the command cmd on slot index) and awaits its answer: onDone, or onFail with the
	// reason. Inside a Routine (and with block) it waits, and a refusal is an Error; elsewhere it
	// returns at once and a refusal is posted as an ERROR when it comes. block false: never waits
	// and does not need the server marked running (at ServerBoot, re-opening, it is not yet).
	*send { |server, cmd, index, msg, onDone, onFail, block = true|
		this.sendSequence(server, index, [[cmd, msg]], onDone, onFail, block)
	}

	// Sends steps ([cmd, msg] pairs, all on slot index) one after the other, each once the one
	// before succeeded, and answers once for all, as send does: onDone when the last succeeded;
	// at the first refusal, the rest are not sent, onFail is called with the reason and the
	// failed step's number, and what it returns (a String: what it undid) ends the refusal's text.
	*sendSequence { |server, index, steps, onDone, onFail, block = true|
		var cond, answer, step, inRoutine = block and: { thisThread.isKindOf(Routine) };
		if(server.isNil) { ^this };
		if(block) { FrictionCheck.serverRunning(server, "FrictionDevice") };
		cond = Condition(false);
		step = { |i|
			var cmd, msg;
			if(i >= steps.size) {
				answer = \done;
				onDone.value;
				cond.test = true; cond.signal;
			} {
				#cmd, msg = steps[i];
				this.expect(server, cmd, index, { step.(i + 1) }, { |reason|
					var undone = onFail.value(reason, i);
					answer = this.failText(cmd, reason) ++ (if(undone.isString) { "; " ++ undone } { "" });
					if(inRoutine.not) { ("ERROR: " ++ answer).postln };
					cond.test = true; cond.signal;
				});
				server.listSendMsg(msg);
			}
		};
		step.(0);
		if(inRoutine) {
			cond.wait;
			if(answer != \done) { Error(answer).throw };
		};
	}

	// Calls done when /kfDone for cmd and the slot comes, fail with the reason when /kfFail for
	// them comes or nothing came within timeout s.
	*expect { |server, cmd, index, done, fail|
		var list = pending[server] ?? { List.new };
		var entry = (cmd: cmd, index: index, done: done, fail: fail);
		pending[server] = list;
		list.add(entry);
		responders[server] ?? {
			responders[server] = [
				OSCFunc({ |msg|
					var found = this.awaiting(list, this.textOf(msg).asSymbol, msg[2]);
					found !? { list.remove(found); found[\done].value };
				}, '/kfDone', server.addr).permanent_(true),
				OSCFunc({ |msg|
					var reason = this.textOf(msg);
					var found = this.awaiting(list, reason.split($:).first.asSymbol, msg[2]);
					found !? { list.remove(found); found[\fail].value(reason) };
				}, '/kfFail', server.addr).permanent_(true)
			]
		};
		SystemClock.sched(timeout, {
			if(list.includes(entry)) {
				list.remove(entry);
				fail.value("no answer from % in % s".format(server, timeout));
			};
			nil
		});
	}

	// The text of a /kfDone or /kfFail: character codes after node and reply ID.
	*textOf { |msg| ^msg[3..].collect { |c| c.asInteger.asAscii }.join }

	// The first command cmd awaiting an answer for device index: a reply ID of -1 is a refusal of
	// the device argument itself (or a command without one, kfListMice), for any slot.
	*awaiting { |list, cmd, index|
		^list.detect { |e| e[\cmd] == cmd and: { index < 0 or: { e[\index] == index } } }
	}

	// Fails every command still awaiting an answer from server (it quit: none will come).
	*failAll { |server, reason|
		pending[server] !? { |list| list.copy.do { |e| list.remove(e); e[\fail].value(reason) } };
	}

	// The server's reasons name their command already ("kfOpenSim: ..."); ours do not.
	*failText { |cmd, reason|
		^if(reason.beginsWith(cmd.asString ++ ":")) {
			"FrictionDevice " ++ reason
		} {
			"FrictionDevice %: %".format(cmd, reason)
		}
	}
}
