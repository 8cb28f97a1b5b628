"""Helpers for benchmark scripts: run a command and measure wall time and peak RSS."""
import os
import subprocess
import time


def run_measured(cmd, env=None, cwd=None, log_path=None):
    """Run ``cmd``; return (exit code, wall seconds, peak RSS in MiB of the child)."""
    out = open(log_path, "w") if log_path else subprocess.DEVNULL
    t0 = time.time()
    proc = subprocess.Popen(cmd, env=env, cwd=cwd, stdout=out, stderr=subprocess.STDOUT)
    _, status, usage = os.wait4(proc.pid, 0)
    wall = time.time() - t0
    proc.returncode = os.waitstatus_to_exitcode(status)
    if log_path:
        out.close()
    return proc.returncode, wall, usage.ru_maxrss / 1024.0
