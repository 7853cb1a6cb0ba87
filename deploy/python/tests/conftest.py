"""What the tests share: a child Python process that cannot outlive its test."""
import subprocess
import sys
import threading

import pytest


@pytest.fixture
def child():
    """`child(code_or_path, *args, seconds=120)` starts `python3 -c CODE ARGS...` (or
    a script's path), its standard output and error as text pipes. A watchdog kills it
    after `seconds` (a run that did not stop would go on for a day, or a callable block
    for a minute: the test then fails instead of waiting), and so does the end of the
    test."""
    started = []

    def start(program, *args, seconds=120):
        head = ["-c", program] if "\n" in program else [program]
        p = subprocess.Popen([sys.executable, *head, *map(str, args)],
                             stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
        watchdog = threading.Timer(seconds, p.kill)
        watchdog.start()
        started.append((p, watchdog))
        return p

    yield start
    for p, watchdog in started:
        watchdog.cancel()
        if p.poll() is None:
            p.kill()
        p.wait()
