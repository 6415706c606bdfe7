"""fovea-server as a child process on a free loopback port, for the
Python client's end-to-end tests (example_test.py, tls_test.py).

A port found free can be taken before the child binds it, for example as
the source port of another test's connection; a child that exits early is
started again on a fresh port, twice at most.
"""

import socket
import subprocess
import time


def free_port():
    """A TCP port on 127.0.0.1 that was free a moment ago."""
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def start_serving(args, is_serving, timeout_s=60.0, attempts=3):
    """Starts `args` plus --listen on a free port and waits until
    `is_serving(target)` is true. Returns (process, target). Raises
    AssertionError, after stopping the child, when it never serves."""
    process = None
    for _ in range(attempts):
        target = f"127.0.0.1:{free_port()}"
        process = subprocess.Popen([*args, f"--listen={target}"])
        deadline = time.monotonic() + timeout_s
        while time.monotonic() < deadline and process.poll() is None:
            if is_serving(target):
                return process, target
            time.sleep(0.1)
        if process.poll() is None:
            break  # alive but not serving: another port would not help
    if process.poll() is None:
        process.kill()
        process.wait()
    raise AssertionError(f"fovea-server not SERVING within {timeout_s:.0f} s "
                         f"(exit code {process.returncode})")


def stop(process):
    """SIGTERM, then SIGKILL after 30 s."""
    if process.poll() is None:
        process.terminate()
        try:
            process.wait(timeout=30)
        except subprocess.TimeoutExpired:
            process.kill()
            process.wait()
