"""Helpers for benchmark scripts: run a command and measure wall time and peak RSS."""
import os
import subprocess
import threading
import time

LAST_RUN = {}  # run_measured's last child: {"cpu": user + system CPU seconds} (load-independent, unlike the wall)


def run_measured(cmd, env=None, cwd=None, log_path=None):
    """Run ``cmd``; return (exit code, wall seconds, peak RSS in MiB of the child); the child's CPU seconds go
    to ``LAST_RUN["cpu"]``."""
    out = open(log_path, "w") if log_path else subprocess.DEVNULL
    t0 = time.time()
    proc = subprocess.Popen(cmd, env=env, cwd=cwd, stdout=out, stderr=subprocess.STDOUT)
    _, status, usage = os.wait4(proc.pid, 0)
    wall = time.time() - t0
    proc.returncode = os.waitstatus_to_exitcode(status)
    LAST_RUN["cpu"] = usage.ru_utime + usage.ru_stime
    if log_path:
        out.close()
    return proc.returncode, wall, usage.ru_maxrss / 1024.0


def tree_rss(root_pid):
    """Sum of RSS (bytes) of a process and all its descendants (Linux /proc)."""
    parents = {}
    rss = {}
    page = os.sysconf("SC_PAGE_SIZE")
    for d in os.listdir("/proc"):
        if not d.isdigit():
            continue
        try:
            with open(f"/proc/{d}/stat") as f:
                st = f.read()
            fields = st[st.rfind(")") + 2:].split()
            parents[int(d)] = int(fields[1])
            rss[int(d)] = int(fields[21]) * page
        except (OSError, IndexError, ValueError):
            continue
    tree = {root_pid}
    changed = True
    while changed:
        changed = False
        for pid, ppid in parents.items():
            if ppid in tree and pid not in tree:
                tree.add(pid)
                changed = True
    return sum(rss.get(p, 0) for p in tree), len(tree)


def run_tree_measured(cmd, env=None, log_path=None, interval=0.2, peak_at=None):
    """Run ``cmd``; return (exit code, wall seconds, peak summed RSS in MiB of the child and all its
    descendants (pool workers), sampled every ``interval`` s).  ``peak_at``: a list that receives the
    seconds after the start at which the peak was seen."""
    out = open(log_path, "w") if log_path else subprocess.DEVNULL
    t0 = time.time()
    proc = subprocess.Popen(cmd, env=env, stdout=out, stderr=subprocess.STDOUT)
    peak = [0]
    stop = threading.Event()

    when = [0.0]

    def sample():
        while not stop.wait(interval):
            rss = tree_rss(proc.pid)[0]
            if rss > peak[0]:
                peak[0], when[0] = rss, time.time() - t0

    th = threading.Thread(target=sample, daemon=True)
    th.start()
    _, status, usage = os.wait4(proc.pid, 0)
    stop.set()
    th.join()
    if log_path:
        out.close()
    if peak_at is not None:
        peak_at.append(when[0])
    return os.waitstatus_to_exitcode(status), time.time() - t0, max(peak[0] / 2 ** 20, usage.ru_maxrss / 1024.0)
