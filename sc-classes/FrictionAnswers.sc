// The answers to FrictionDevice's asynchronous commands (the plugin's CommandRunner): /done with
// the command's name when it succeeded, /kfFail (node 0, reply ID the slot, then the reason as
// character codes, starting with the command's name) when the server refused it, whatever was
// wrong; nothing only when the server is gone, so a timeout.
// One pair of responders per server; the commands awaiting an answer, by server, in the order
// they were sent.
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
		var cond, answer, inRoutine = block and: { thisThread.isKindOf(Routine) };
		if(server.isNil) { ^this };
		if(block) { FrictionCheck.serverRunning(server, "FrictionDevice") };
		cond = Condition(false);
		this.expect(server, cmd, index, {
			answer = \done;
			onDone.value;
			cond.test = true; cond.signal;
		}, { |reason|
			answer = reason;
			onFail.value(reason);
			if(inRoutine.not) { ("ERROR: " ++ this.failText(cmd, reason)).postln };
			cond.test = true; cond.signal;
		});
		server.listSendMsg(msg);
		if(inRoutine) {
			cond.wait;
			if(answer != \done) { Error(this.failText(cmd, answer)).throw };
		};
	}

	// Calls done when /done cmd comes, fail with the reason when /kfFail for the slot comes or
	// nothing came within timeout s.
	*expect { |server, cmd, index, done, fail|
		var list = pending[server] ?? { List.new };
		var entry = (cmd: cmd, index: index, done: done, fail: fail);
		pending[server] = list;
		list.add(entry);
		responders[server] ?? {
			responders[server] = [
				OSCFunc({ |msg|
					var found = list.detect { |e| e[\cmd] == msg[1] };
					found !? { list.remove(found); found[\done].value };
				}, '/done', server.addr).permanent_(true),
				OSCFunc({ |msg|
					var reason = msg[3..].collect { |c| c.asInteger.asAscii }.join;
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

	// The first command cmd awaiting an answer for device index: a refusal's reply ID is -1 when
	// the device argument itself was wrong (or the command has none, kfListMice).
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
