"""How long a Ctrl-C takes to reach a run whose operator blocks (docs/15-python.md):
a child Python runs a 1,000-sample scenario whose operator, at sample 200, sleeps a
minute, waits on a socket nothing writes to, or loops in Python; SIGINT is sent and
the time until the child says KeyboardInterrupt (its report written) is measured.
Usage, with the package importable: python3 deploy/python/bench/ctrl_c.py [REPEATS]
(`ctrl_c.py child OUT HOW` is the child, which tests/test_in_the_loop.py runs too)."""
import signal
import subprocess
import sys
import tempfile
import time
import traceback

HOWS = ["sleep", "recv", "spin"]


def child(out: str, how: str) -> None:
    """The run whose operator blocks at sample 200 (`how`), into `out`; prints
    `blocking` then, and `KeyboardInterrupt in FRAME` with the frame it was raised in."""
    import socket
    import tactile
    # Python's own handler, whatever the parent ignored (a background job of a
    # non-interactive shell starts with SIGINT ignored).
    signal.signal(signal.SIGINT, signal.default_int_handler)
    a, _ = socket.socketpair()

    def operator(n, t, felt):
        if n == 200:
            print("blocking", flush=True)
            if how == "sleep":
                time.sleep(60)
            elif how == "recv":
                a.recv(1)
            else:
                while True:
                    pass
        return (0.0, 0.15, 0.05)

    sc = tactile.Scenario.paper().with_set({"samples": 1000})
    try:
        tactile.run(sc, out=out, operator=operator)
    except KeyboardInterrupt as e:
        print("KeyboardInterrupt in", traceback.extract_tb(e.__traceback__)[-1].name,
              flush=True)


def main(repeats: int) -> None:
    for how in HOWS:
        took = []
        for _ in range(repeats):
            with tempfile.TemporaryDirectory() as d:
                p = subprocess.Popen([sys.executable, __file__, "child", d + "/run", how],
                                     stdout=subprocess.PIPE, text=True)
                assert p.stdout.readline().strip() == "blocking"
                time.sleep(0.2)
                sent = time.monotonic()
                p.send_signal(signal.SIGINT)
                said = p.stdout.readline().strip()
                took.append(time.monotonic() - sent)
                p.wait()
                assert said == "KeyboardInterrupt in operator", said
        print(f"{how}: " + ", ".join(f"{t * 1e3:.0f} ms" for t in took))


if __name__ == "__main__":
    if sys.argv[1:2] == ["child"]:
        child(sys.argv[2], sys.argv[3])
    else:
        main(int(sys.argv[1]) if len(sys.argv) > 1 else 5)
