"""What the benchmarks print about where they ran: the processor and its load."""

from __future__ import annotations

import platform
import subprocess


def processor() -> str:
    """The model name `lscpu` gives, or what the platform module knows."""
    try:
        out = subprocess.run(["lscpu"], capture_output=True, text=True, check=True).stdout
        return next(l.split(":", 1)[1].strip() for l in out.splitlines() if l.startswith("Model name"))
    except (OSError, subprocess.CalledProcessError, StopIteration):
        return platform.processor() or "unknown processor"


def load() -> str:
    """The load averages over 1, 5 and 15 minutes."""
    try:
        with open("/proc/loadavg") as f:
            return "load average " + " ".join(f.read().split()[:3])
    except OSError:
        return "load average unknown"


def machine() -> str:
    return f"{processor()}; {load()}"
