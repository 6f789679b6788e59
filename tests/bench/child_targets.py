"""Functions the harness tests run in a child interpreter (this folder is put on its PYTHONPATH)."""

import os
import signal
import time


def sleep(seconds: float) -> float:
    """Sleep [s] (longer than a test's timeout: a stand-in for a hung child)."""
    time.sleep(seconds)
    return seconds


def fail(message: str) -> None:
    raise ValueError(message)


def die(how: str) -> None:
    """Leave without a result: ``"exit"`` (exit code 3, no traceback) or ``"signal"`` (SIGKILL)."""
    if how == "exit":
        os._exit(3)
    os.kill(os.getpid(), signal.SIGKILL)


def rftstatic_file() -> dict:
    """Where the child's rftstatic comes from, and what it printed to stdout meanwhile."""
    import numpy as np

    import rftstatic

    print("noise on stdout")
    return {"file": rftstatic.__file__, "array": np.arange(3), "scalar": np.float32(0.5), "tuple": (1, 2)}
