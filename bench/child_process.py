"""A child process's CPU time (user and system, from wait4) and peak memory, for the benchmarks
that run `flexure` whole."""

import os
import subprocess
import sys


def child_cpu(cmd):
    """(CPU seconds, peak MB) of running cmd; exits with its stderr if it fails."""
    p = subprocess.Popen(cmd, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE)
    _, status, ru = os.wait4(p.pid, 0)
    err = p.stderr.read().decode()
    p.stderr.close()
    if status != 0:
        sys.exit("%s failed: %s" % (" ".join(cmd), err))
    return ru.ru_utime + ru.ru_stime, ru.ru_maxrss / 1024.0
