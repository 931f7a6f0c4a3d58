# The solver runs with the GIL released: another Python thread keeps running during a run.
import sys
import threading
import time

import furrow


def test_run_does_not_block_other_threads(small_plate, tmp_path):
    """With a switch interval far longer than the run, a thread waiting for the GIL would get it
    only when the running thread gives it up: counts while the run holds it would stay at zero."""
    count = 0
    done = threading.Event()

    def counter():
        nonlocal count
        while not done.is_set():
            count += 1
            time.sleep(0)  # gives up the GIL on every round

    calls = []
    old = sys.getswitchinterval()
    sys.setswitchinterval(1000.0)
    t = threading.Thread(target=counter)
    try:
        t.start()
        before = count
        s = furrow.run(small_plate, tmp_path / "run", progress=lambda p: calls.append(count), progress_interval_s=0.02)
        after = count
    finally:
        done.set()
        t.join()
        sys.setswitchinterval(old)
    assert not s["stopped"]
    assert len(calls) >= 2  # the progress callback ran while the solver did
    assert after - before >= 100, f"the other thread counted {after - before} times during the run"
