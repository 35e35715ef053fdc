"""A small job pool for the study scripts (eta_inf.py, trends.py, extremes.py, tradeoff.py): runs
fdsusp cases side by side, at most `jobs` at a time, and reports each one's exit status and the
CPU seconds it used (its own rusage, so the cost of a case does not depend on what ran beside it).

    from jobpool import ENV, run_all, start_resumable
    results = run_all(cases, start, jobs)   # {case: (status, cpu_seconds)}

start(case) must return a subprocess.Popen (cwd, log and arguments are the caller's); cases are
started in the given order, and each is collected as soon as it ends, whichever it is.
"""
import os
import shutil
import subprocess

# Open MPI refuses to start as root without these (CI and containers run as root).
ENV = dict(os.environ, OMPI_ALLOW_RUN_AS_ROOT='1', OMPI_ALLOW_RUN_AS_ROOT_CONFIRM='1')


def run_all(cases, start, jobs, report=None):
    """Run every case; report(case, status, cpu_seconds) is called as each one ends."""
    waiting, running, results = list(cases), {}, {}
    while waiting or running:
        while waiting and len(running) < max(1, jobs):
            case = waiting.pop(0)
            proc = start(case)
            running[proc.pid] = (case, proc)
        pid, status, usage = os.wait4(-1, 0)
        if pid not in running:          # a child the caller started itself: not ours to report
            continue
        case, proc = running.pop(pid)
        proc.returncode = os.waitstatus_to_exitcode(status)
        cpu = usage.ru_utime + usage.ru_stime
        results[case] = (proc.returncode, cpu)
        if report is not None:
            report(case, proc.returncode, cpu)
    return results


def start_resumable(d, deck, ranks=1):
    """Start fdsusp on deck (its text) in directory d, a case of a resumable study: the program is
    copied into d at the first start ($FDSUSP_BIN, else bin/ of this checkout), so that a rebuild
    cannot change a case half-way; a case with out/checkpoint.h5 continues from it (-restart); the
    log (d/log) is appended to. Returns (Popen, fresh): fresh when the program was copied now."""
    os.makedirs(d, exist_ok=True)
    binary = os.path.join(d, 'fdsusp')
    fresh = not os.path.exists(binary)
    if fresh:
        root = os.path.abspath(os.path.join(os.path.dirname(__file__), '..'))
        shutil.copy2(os.path.join(os.environ.get('FDSUSP_BIN', os.path.join(root, 'bin')), 'fdsusp'), binary)
    with open(os.path.join(d, 'deck.nml'), 'w') as f:
        f.write(deck)
    command = [binary, 'deck.nml']
    if ranks > 1:
        command = ['mpirun', '--oversubscribe', '-n', str(ranks)] + command
    if os.path.exists(os.path.join(d, 'out', 'checkpoint.h5')):
        command += ['-restart', 'out/checkpoint.h5']
    log = open(os.path.join(d, 'log'), 'a')
    log.write('\n# %s\n' % ' '.join(command))
    log.flush()
    return subprocess.Popen(command, cwd=d, env=ENV, stdout=log, stderr=subprocess.STDOUT), fresh
