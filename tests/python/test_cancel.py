# SPDX-License-Identifier: Apache-2.0
"""Progress, cancellation and Ctrl-C: a progress callback that returns
False cancels through the library (CancelledError, nothing written); one
that raises has its exception re-raised; SIGINT in a process running a
long pack ends it within a second or two with KeyboardInterrupt and no
output."""
import os
import signal
import subprocess
import sys
import textwrap
import threading
import time

import numpy as np
import pytest

import vdbpack
from conftest import SAMPLES


def test_progress_is_reported_from_the_worker():
    seen = []
    main = threading.current_thread()

    def progress(fraction, stage):
        seen.append((fraction, stage, threading.current_thread() is main))

    p = vdbpack.pack("box:1,1,1", method="rsa", radius=0.03, count="max", progress=progress)
    assert len(p) > 1000 and seen
    assert all(0.0 <= f <= 1.0 and isinstance(s, str) for f, s, _ in seen)
    assert not any(on_main for _, _, on_main in seen)  # the caller only waits


def test_false_cancels_the_pack():
    calls = []

    def progress(fraction, stage):
        calls.append(fraction)
        return len(calls) < 3

    with pytest.raises(vdbpack.CancelledError) as e:
        # uncancelled, some 30 s and 100 MB
        vdbpack.pack("box:1,1,1", method="rsa", radius=0.004, count="max", progress=progress)
    assert e.value.code == "VP_ERR_CANCELLED" and str(e.value)
    assert len(calls) == 3  # cancelled at the first False: no call after it
    # the module is fine afterwards
    assert len(vdbpack.pack("box:1,1,1", radius=0.2)) == 14


def test_cancelled_writes_leave_no_file(tmp_path):
    p = vdbpack.pack("box:1,1,1", method="rsa", radius=0.02, count=20000)
    obj = tmp_path / "big.obj"
    with pytest.raises(vdbpack.CancelledError):
        p.write(str(obj), progress=lambda f, s: False)  # at its first report
    png = tmp_path / "big.png"
    with pytest.raises(vdbpack.CancelledError):
        p.render(str(png), size=(320, 200), progress=lambda f, s: f < 0.1)
    assert list(tmp_path.iterdir()) == []  # no output, no temporary file


class Boom(Exception):
    pass


def test_an_exception_in_the_callback_is_raised():
    def progress(fraction, stage):
        raise Boom("from the callback at %s" % stage)

    with pytest.raises(Boom, match="from the callback"):
        vdbpack.pack("box:1,1,1", method="rsa", radius=0.03, count=500, progress=progress)
    with pytest.raises(Boom):
        vdbpack.Container.from_file(os.path.join(SAMPLES, "peanut.obj"), progress=progress)


def test_a_failing_distance_function_stops_the_call():
    def ball(x, y, z):
        return (x * x + y * y + z * z) ** 0.5 - 1.0

    c = vdbpack.Container.from_function(ball, (-1, -1, -1), (1, 1, 1), 4 / 3 * np.pi)
    p = vdbpack.pack(c, method="rsa", radius=0.1, count=100, threads=2)
    assert np.all(np.linalg.norm(p.positions, axis=1) + p.radii <= 1 + 1e-6)
    np.testing.assert_allclose(c.distance(p.positions), np.linalg.norm(p.positions, axis=1) - 1)
    calls = [0]

    def flaky(x, y, z):
        calls[0] += 1
        if calls[0] > 2000:
            raise Boom("the sampler failed")
        return ball(x, y, z)

    c = vdbpack.Container.from_function(flaky, (-1, -1, -1), (1, 1, 1), 4 / 3 * np.pi)
    with pytest.raises(Boom, match="the sampler failed"):
        vdbpack.pack(c, method="rsa", radius=0.02, count="max", threads=2)
    nan = vdbpack.Container.from_function(lambda x, y, z: float("nan"), (-1, -1, -1),
                                          (1, 1, 1), 1.0)
    with pytest.raises(ValueError, match="returned nan"):
        nan.distance((0, 0, 0))


SCRIPT = textwrap.dedent("""
    import sys, vdbpack
    out = sys.argv[1]
    said = []
    def progress(fraction, stage):
        if not said:
            said.append(1)
            print("started", flush=True)
    # minutes of work uncancelled (a relaxation reports progress about every
    # second, at most; the first time after about a second)
    p = vdbpack.pack("box:1,1,1", method="relax", radius=0.01, count=30000,
                     target_fraction=0.62, progress=progress)
    p.write(out)
    print("finished", flush=True)
""")


def test_ctrl_c_cancels_a_long_pack(tmp_path):
    out = tmp_path / "never.vdb"
    proc = subprocess.Popen([sys.executable, "-c", SCRIPT, str(out)], stdout=subprocess.PIPE,
                            stderr=subprocess.PIPE, text=True)
    try:
        line = proc.stdout.readline()
        assert line.strip() == "started", (line, proc.stderr.read() if proc.poll() else "")
        time.sleep(0.3)
        t0 = time.monotonic()
        proc.send_signal(signal.SIGINT)
        rc = proc.wait(timeout=30)
        took = time.monotonic() - t0
    finally:
        if proc.poll() is None:
            proc.kill()
            proc.wait()
    err = proc.stderr.read()
    # Python ends an uncaught KeyboardInterrupt by dying of SIGINT itself
    assert rc == -signal.SIGINT, (rc, err)
    assert err.rstrip().splitlines()[-1] == "KeyboardInterrupt", err
    assert "finished" not in proc.stdout.read()
    # generous: the machine may be busy; "never" is the 30 s timeout above
    assert took < 20, took
    assert list(tmp_path.iterdir()) == []
