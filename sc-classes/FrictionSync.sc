// A wait for the server to have done what it was sent (its /synced), bounded and asked again.
// Server.sync waits for one answer for ever: over UDP a /sync or its /synced can be lost (a
// receive buffer full while sclang or the server stood still), and the routine then hangs with
// nothing posted, while a study's watch, whose own /sync goes out every 0.25 s, sees the server
// answer. Here the /sync goes out again every askEveryS until an answer to any of them comes (the
// server answers each only after everything sent before it, so a later one says as much), and
// after timeoutS without one the wait is an Error that names the call.
FrictionSync {
	classvar <>askEveryS = 0.25;

	// Inside a Routine: returns once the server has answered, or throws after timeoutS.
	*wait { |server, timeoutS = 5, where = "FrictionSync.wait"|
		var id = UniqueID.next, answered = false, t0 = Main.elapsedTime, responder, cond;
		if(thisThread.isKindOf(Routine).not) { Error("%: call it inside a Routine (fork)".format(where)).throw };
		responder = OSCFunc({ answered = true; cond !? { cond.test = true; cond.signal } }, '/synced', server.addr,
			argTemplate: [id]);
		// Freed here whichever way the wait ends; and after the bound, should the Routine be
		// stopped while it waits (a study session that failed).
		SystemClock.sched(timeoutS + askEveryS, { responder.free; nil });
		while { answered.not and: { Main.elapsedTime - t0 < timeoutS } } {
			var asked = Condition(false);
			cond = asked;
			server.sendMsg('/sync', id);
			SystemClock.sched(askEveryS, { asked.test = true; asked.signal; nil });
			asked.wait;
		};
		responder.free;
		if(answered.not) {
			Error("%: the server % did not answer a /sync in % s".format(where, server.name, timeoutS)).throw
		};
	}
}
