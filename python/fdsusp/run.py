"""Where fdsusp's programs are, and running them.

program('fdsusp') is the one way to find a program (fdsusp, fdsusp-pack, fdsusp-resistance,
pairtraj), in this order:
  1. $FDSUSP_BIN, when set (a pinned build, or an installed PREFIX/bin: `FDSUSP_BIN=... make check`);
  2. bin/ of the checkout this package lives in (python/fdsusp/ of a checkout, also when installed
     with `pip install -e .`);
  3. PREFIX/bin beside an installed package (`make install`: PREFIX/share/fdsusp/python/fdsusp);
  4. the PATH.

command() and run() start fdsusp on a deck (under mpiexec with more than one rank); run_all() and
start_resumable() are the small job pool of the study scripts: cases side by side, at most `jobs`
at a time, each one's exit status and the CPU seconds it used (its own rusage, so the cost of a
case does not depend on what ran beside it).
"""
import os
import shutil
import subprocess

_HERE = os.path.dirname(os.path.abspath(__file__))

# Open MPI refuses to start as root without these (CI and containers run as root).
ENV = dict(os.environ, OMPI_ALLOW_RUN_AS_ROOT='1', OMPI_ALLOW_RUN_AS_ROOT_CONFIRM='1')
MPIEXEC = ['mpiexec', '--oversubscribe']
PROGRAMS = ('fdsusp', 'fdsusp-pack', 'fdsusp-resistance', 'pairtraj')


def checkout():
    """The root of the checkout this package lives in (python/fdsusp/ under it), else None."""
    root = os.path.dirname(os.path.dirname(_HERE))
    return root if os.path.isdir(os.path.join(root, 'src', 'programs')) else None


def _installed_bin():
    """PREFIX/bin of an installed package (PREFIX/share/fdsusp/python/fdsusp), when it holds fdsusp."""
    prefix = os.path.normpath(os.path.join(_HERE, '..', '..', '..', '..'))
    b = os.path.join(prefix, 'bin')
    return b if os.path.isfile(os.path.join(b, 'fdsusp')) else None


def bin_dir():
    """The directory of the programs (module doc: FDSUSP_BIN, the checkout, the install, PATH);
    None when none of them is found."""
    env = os.environ.get('FDSUSP_BIN')
    if env:
        return env
    root = checkout()
    if root is not None:
        return os.path.join(root, 'bin')
    installed = _installed_bin()
    if installed is not None:
        return installed
    found = shutil.which('fdsusp')
    return os.path.dirname(found) if found else None


def program(name='fdsusp'):
    """The path of one of fdsusp's programs (module doc). FileNotFoundError when no place is known."""
    d = bin_dir()
    if d is None:
        raise FileNotFoundError(f'{name}: not found (set FDSUSP_BIN to the directory of the programs)')
    return os.path.join(d, name)


def command(deck, ranks=1, args=(), binary=None):
    """The command line running fdsusp (or binary) on deck, under mpiexec when ranks > 1."""
    cmd = [binary or program('fdsusp'), deck] + list(args)
    if ranks > 1:
        cmd = MPIEXEC + ['-n', str(ranks)] + cmd
    return cmd


def run(deck, cwd=None, ranks=1, args=(), env=None, timeout=None, binary=None):
    """Run fdsusp on deck in cwd and wait: a subprocess.CompletedProcess with stdout and stderr."""
    return subprocess.run(command(deck, ranks, args, binary), cwd=cwd, env=env or ENV, capture_output=True,
                          text=True, timeout=timeout)


def copy_program(destination, name='fdsusp'):
    """Copy a program (program(name)) to destination: a study pins the build it started with."""
    shutil.copy2(program(name), destination)


def run_all(cases, start, jobs, report=None):
    """Run every case: start(case) returns a subprocess.Popen (cwd, log and arguments are the
    caller's); cases start in the given order, at most jobs at a time, and each is collected as
    soon as it ends, whichever it is; report(case, status, cpu_seconds) is called as each one ends.
    Returns {case: (status, cpu_seconds)}."""
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
    copied into d at the first start (program('fdsusp')), so that a rebuild cannot change a case
    half-way; a case with out/checkpoint.h5 continues from it (-restart); the log (d/log) is
    appended to. Returns (Popen, fresh): fresh when the program was copied now."""
    os.makedirs(d, exist_ok=True)
    binary = os.path.join(d, 'fdsusp')
    fresh = not os.path.exists(binary)
    if fresh:
        copy_program(binary)
    with open(os.path.join(d, 'deck.nml'), 'w') as f:
        f.write(deck)
    args = ['-restart', 'out/checkpoint.h5'] if os.path.exists(os.path.join(d, 'out', 'checkpoint.h5')) else []
    cmd = command('deck.nml', ranks, args, binary=binary)
    log = open(os.path.join(d, 'log'), 'a')
    log.write('\n# %s\n' % ' '.join(cmd))
    log.flush()
    return subprocess.Popen(cmd, cwd=d, env=ENV, stdout=log, stderr=subprocess.STDOUT), fresh
