"""FrictionSync.wait, against a stand-in server (a UDP socket here) that answers a /sync as told:
the first at once, only the second (the first answer lost), or never. A lost answer is asked
for again and the wait goes on; no answer at all is an Error naming the call, after its bound."""
import socket
import struct
import threading

from kfharness import sclang


def osc_string(text):
    data = text.encode() + b"\0"
    return data + b"\0" * (-len(data) % 4)


class StandInServer:
    """Answers /sync <id> with /synced <id>, except the ones `answer(n)` refuses (n counts from 1)."""

    def __init__(self, answer):
        self.answer = answer
        self.asked = []  # the ids of the /syncs that came
        self.sock = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
        self.sock.bind(("127.0.0.1", 0))
        self.sock.settimeout(0.1)
        self.port = self.sock.getsockname()[1]
        self.running = True
        self.thread = threading.Thread(target=self.serve, daemon=True)
        self.thread.start()

    def serve(self):
        while self.running:
            try:
                data, sender = self.sock.recvfrom(65536)
            except socket.timeout:
                continue
            if not data.startswith(osc_string("/sync") + osc_string(",i")):
                continue
            sync_id = struct.unpack(">i", data[-4:])[0]
            self.asked.append(sync_id)
            if self.answer(len(self.asked)):
                self.sock.sendto(osc_string("/synced") + osc_string(",i") + struct.pack(">i", sync_id), sender)

    def stop(self):
        self.running = False
        self.thread.join()
        self.sock.close()


def test_a_lost_answer_is_asked_for_again_and_none_is_an_error():
    servers = {"once": StandInServer(lambda n: True), "second": StandInServer(lambda n: n == 2),
               "never": StandInServer(lambda n: False)}
    try:
        out = sclang.run_script("\n".join(f"""
            ~server = Server(\\kfStandIn{name}, NetAddr("127.0.0.1", {server.port}));
            ~t0 = Main.elapsedTime;
            try {{ FrictionSync.wait(~server, 1, "KF-test {name}"); "KF-SYNC {name} returned".postln }} {{ |error|
                ("KF-SYNC {name} error " ++ error.errorString).postln }};
            "KF-SYNC {name} after % s".format((Main.elapsedTime - ~t0).round(0.01)).postln;
        """ for name, server in servers.items()), routine=True)
    finally:
        for server in servers.values():
            server.stop()
    said = {line.split()[1]: line for line in out.splitlines() if line.startswith("KF-SYNC ") and "after" not in line}
    took = {line.split()[1]: float(line.split()[3]) for line in out.splitlines() if " after " in line}
    assert said["once"].endswith("returned") and len(servers["once"].asked) == 1
    # The second /sync, FrictionSync.askEveryS (0.25 s) after the first, with the same id.
    assert said["second"].endswith("returned"), out[-3000:]
    assert len(servers["second"].asked) == 2 and len(set(servers["second"].asked)) == 1
    assert 0.2 < took["second"] < 0.9, took
    # Asked every 0.25 s until its bound of 1 s, then the Error names the call and the bound.
    assert "ERROR: KF-test never: the server kfStandInnever did not answer a /sync in 1 s" in said["never"], out[-3000:]
    assert 4 <= len(servers["never"].asked) <= 5 and 1.0 <= took["never"] < 2.0, (servers["never"].asked, took)
