"""Invariant: a run carried by a chain of batch jobs (scripts/slurm/fdsusp.sbatch) ends exactly where
the uninterrupted run ends, whatever stops its jobs, signals sent the way they arrive on a cluster:
 0. a run from the start killed outright (SIGKILL, 1 rank) before its first periodic checkpoint
    leaves checkpoint.h5 whole, at step 0: a run from the start publishes its initial state before
    its first step (before this, such a kill left no checkpoint, and one killed while writing its
    first left only checkpoint.h5.tmp);
 1. job 1 starts the deck from the beginning (-continue finds no checkpoint) and first queues its
    successor (--dependency=afterany on itself). SIGTERM sent to mpiexec itself (what a batch
    system sends at the limit, or a user) ends it the way Open MPI does (README "Batch jobs"):
    mpiexec's status 1, SIGTERM to the ranks 1 s later and SIGKILL 1 s after that, here before the
    first periodic checkpoint. checkpoint.h5 is whole: the initial state, or the checkpoint the
    ranks wrote on their SIGTERM if they finished it within that second (either happens), never
    a checkpoint.h5.tmp alone. The job sees no fdsusp error, so it leaves its successor queued;
 2. job 2 continues from that checkpoint (removing a partial checkpoint.h5.tmp the kill left);
    SIGUSR1 to the job's shell (what Slurm's --signal=B:USR1@300 sends before the time limit)
    reaches the ranks through mpiexec: the run stops at the end of a step with a checkpoint,
    fdsusp's status 0, the job ends 0 and leaves its successor queued;
 3. job 3 continues to the deck's last step, says the run is done and cancels its successor;
 4. every dataset and attribute of the chain's final checkpoint and series.h5 (wall_time excepted)
    equals those of one uninterrupted run of the same deck to 1e-12 of its largest magnitude (at
    least 1; bitwise in practice: restarts are exact, test_restart).
sbatch and scancel are stand-ins that record their calls (FDSUSP_SUBMIT, FDSUSP_CANCEL); the
successor 'Slurm would start' is started here by hand with the environment the stand-in was given.
Set-up: the three spheres of test_contact_restart (contacts with friction, full lubrication), the
rank count of the suite (make check RANKS=n) for the chain and the reference alike, 3000 steps, a checkpoint every 2500, so that the kill of job 1 comes before the first and
before the end: Open MPI lets the ranks run ~1 s after the SIGTERM, and since the direct fluid
solves (issue 31) this scene takes 2-4 ms per step (with 100 steps, job 1 had finished the run)"""
import os
import signal
import subprocess
import time

import h5py
import numpy as np

import fdsusp_testlib as T

STEPS = 3000
DECK = """&domain box = 6.4, 6.4, 6.4, cells_per_radius = 5, y_boundary = 'walls', shear_rate = 1 /
&fluid reynolds = 0.01, initial_flow = 'shear', velocity_tolerance = 1e-12, pressure_tolerance = 1e-12 /
&time dt = 1e-3, steps = %d /
&output directory = 'out', progress_every = 1, checkpoint_every = 2500 /
&particles number = 3,
  position(:,1) = 3.2, 2.2, 3.2, external_force(:,1) = 0, 18.84955592153876, 0,
  position(:,2) = 3.2, 4.206, 3.2, external_force(:,2) = 0, -18.84955592153876, 0,
  position(:,3) = 0.3, 1.006, 3.0, external_force(:,3) = 0, -18.84955592153876, 0 /
&contact roughness = 0.01, normal_stiffness = 1e5, friction = 0.5 /
""" % STEPS
SCRIPT = os.path.join(T.ROOT, 'scripts', 'slurm', 'fdsusp.sbatch')

started = []


def stop(p):
    """End a job this test started and what it started, each by its pid, deepest first."""
    kids = subprocess.run(['ps', '-o', 'pid=', '--ppid', str(p.pid)], capture_output=True, text=True).stdout.split()
    for k in kids:
        stop(type('P', (), {'pid': int(k)})())
    try:
        os.kill(p.pid, signal.SIGKILL)
    except ProcessLookupError:
        pass


def last_step(log):
    """The last step of a progress line in the log, 0 if none."""
    if not os.path.exists(log):
        return 0
    with open(log) as f:
        steps = [int(l.split()[1]) for l in f if l.startswith('step ') and len(l.split()) > 1]
    return steps[-1] if steps else 0


def job(d, job_id, link):
    """Start scripts/slurm/fdsusp.sbatch as job job_id (the batch shell Slurm would start)."""
    env = dict(T.ENV, SLURM_JOB_ID=str(job_id), FDSUSP_LINK=str(link), FDSUSP=T.FDSUSP,
               FDSUSP_LAUNCH='mpiexec --oversubscribe -n %d' % T.RANKS, FDSUSP_SUBMIT=os.path.join(d, 'sbatch'),
               FDSUSP_CANCEL=os.path.join(d, 'scancel'))
    out = open(os.path.join(d, 'job-%d.out' % job_id), 'w')
    p = subprocess.Popen(['bash', SCRIPT, 'deck.nml'], cwd=d, env=env, stdout=out, stderr=subprocess.STDOUT)
    started.append(p)
    return p, os.path.join(d, 'fdsusp-job-%d.log' % job_id)


def wait_until(p, log, step, timeout=300):
    t0 = time.time()
    while time.time() - t0 < timeout and p.poll() is None:
        if last_step(log) >= step:
            return True
        time.sleep(0.05)
    return False


def kill_mpiexec(p, sig):
    """Send sig to the mpiexec the job's shell started (by its pid)."""
    kids = subprocess.run(['ps', '-o', 'pid=,comm=', '--ppid', str(p.pid)], capture_output=True, text=True).stdout.split()
    pids = [int(kids[i]) for i in range(0, len(kids) - 1, 2) if kids[i + 1].startswith(('mpiexec', 'mpirun', 'orterun'))]
    T.check(len(pids) == 1, 'the job\'s mpiexec found (pid %s)' % pids)
    if pids:
        os.kill(pids[0], sig)


def whole_checkpoint(path, log, what):
    """Check that checkpoint.h5 is whole after a kill; return its step and whether a partial
    checkpoint.h5.tmp lies beside it."""
    tmp = os.path.exists(path + '.tmp')
    try:
        with h5py.File(path, 'r') as f:
            k = int(np.ravel(f.attrs['step'])[0])
            whole = all(n in f for n in ('u', 'v', 'w', 'p', 'particles/position', 'contacts'))
    except (OSError, KeyError) as e:
        k, whole = -1, False
        print('checkpoint unreadable:', e)
    T.check(whole, '%s: checkpoint.h5 is whole after the kill (step %d)%s'
            % (what, k, '; a partial checkpoint.h5.tmp beside it' if tmp else ''))
    return k, tmp


def lines(path):
    return open(path).read().splitlines() if os.path.exists(path) else []


def text(path):
    return open(path).read() if os.path.exists(path) else ''


try:
    # the uninterrupted reference
    ref = T.scratch('batch_chain_reference')
    T.run(T.write_deck(ref, 'deck.nml', DECK), ref, np_ranks=T.RANKS)

    d = T.scratch('batch_chain')
    T.write_deck(d, 'deck.nml', DECK)
    T.write_deck(d, 'sbatch', '#!/bin/bash\n# stand-in for sbatch --parsable: records the call, prints a job id\n'
                 'n=$(( $(cat %s/next_id 2>/dev/null || echo 1001) ))\necho $((n + 1)) > %s/next_id\n'
                 'printf "%%s\\n" "$*" >> %s/submitted\necho "$n"\n' % (d, d, d))
    T.write_deck(d, 'scancel', '#!/bin/bash\nprintf "%%s\\n" "$*" >> %s/cancelled\n' % d)
    os.chmod(os.path.join(d, 'sbatch'), 0o755)
    os.chmod(os.path.join(d, 'scancel'), 0o755)
    checkpoint = os.path.join(d, 'out', 'checkpoint.h5')

    # 0. a run killed outright (SIGKILL) before its first periodic checkpoint leaves a whole one
    z = T.scratch('batch_chain_sigkill')
    zlog = open(os.path.join(z, 'run.log'), 'w+')
    q = subprocess.Popen(T.command(T.write_deck(z, 'deck.nml', DECK)), cwd=z, env=T.ENV, stdout=zlog,
                         stderr=subprocess.STDOUT)
    started.append(q)
    T.check(wait_until(q, zlog.name, 3), 'a run from the start is under way (step %d)' % last_step(zlog.name))
    q.send_signal(signal.SIGKILL)
    q.wait(timeout=60)
    k0, _ = whole_checkpoint(os.path.join(z, 'out', 'checkpoint.h5'), zlog.name, 'SIGKILL at step %d'
                             % last_step(zlog.name))
    T.check(k0 == 0, 'it is the initial state, published before the first step (step %d)' % k0)

    # 1. SIGTERM to mpiexec itself, before the first periodic checkpoint
    p, log = job(d, 1000, 1)
    T.check(wait_until(p, log, 3), 'job 1 runs (step %d)' % last_step(log))
    T.check('-continue: no checkpoint in out yet: starting from the beginning' in text(log),
            'job 1 starts from the beginning (-continue, no checkpoint yet)')
    sub = lines(os.path.join(d, 'submitted'))
    T.check(len(sub) == 1 and '--dependency=afterany:1000' in sub[0] and 'FDSUSP_LINK=2' in sub[0]
            and sub[0].endswith('deck.nml'), 'job 1 queued its successor first: %s' % sub)
    kill_mpiexec(p, signal.SIGTERM)
    status = p.wait(timeout=300)
    T.check(status != 0 and 'killed from outside' in text(os.path.join(d, 'job-1000.out')),
            'job 1: SIGTERM to mpiexec ends the run as Open MPI does (job status %d, last step %d), '
            'the job sees it killed from outside' % (status, last_step(log)))
    T.check(not lines(os.path.join(d, 'cancelled')), 'job 1 left its successor queued')
    k1, tmp1 = whole_checkpoint(checkpoint, log, 'job 1')
    # (the run says so before it writes the checkpoint, and again when it stops, which the SIGKILL
    # a second after the SIGTERM may cut off)
    T.check(k1 == 0 or 'signal 15 at step %d: writing the checkpoint' % k1 in text(log),
            'job 1: the checkpoint is the initial state (step 0) or the one written on the SIGTERM that reached '
            'the ranks before their SIGKILL (step %d)' % k1)

    # 2. SIGUSR1 to the batch shell
    p, log = job(d, 1001, 2)
    T.check(wait_until(p, log, k1 + 10), 'job 2 continues (step %d)' % last_step(log))
    T.check('-continue: continuing from out/checkpoint.h5' in text(log) and 'at step %d,' % k1 in text(log),
            'job 2 continues from the checkpoint of step %d' % k1)
    T.check(('removed checkpoint.h5.tmp' in text(log)) == tmp1 and not os.path.exists(checkpoint + '.tmp'),
            'job 2 removed the partial checkpoint.h5.tmp of the kill (%s)' % ('there was one' if tmp1 else 'none'))
    p.send_signal(signal.SIGUSR1)
    status = p.wait(timeout=300)
    m = [l for l in lines(log) if l.startswith('stopped by signal 10 at step ')]
    k2 = int(m[0].split('at step ')[1].split(':')[0]) if m else -1
    T.check(status == 0 and k2 >= k1 + 10, 'job 2: SIGUSR1 to its shell stops the run at step %d with a '
            'checkpoint, job status %d' % (k2, status))
    T.check(not lines(os.path.join(d, 'cancelled')) and len(lines(os.path.join(d, 'submitted'))) == 2,
            'job 2 queued its successor and left it')
    with h5py.File(checkpoint, 'r') as f:
        T.check(int(np.ravel(f.attrs['step'])[0]) == k2 and not os.path.exists(checkpoint + '.tmp'),
                'checkpoint.h5 is at step %d, no checkpoint.h5.tmp' % k2)

    # 3. the chain's last job
    p, log = job(d, 1002, 3)
    status = p.wait(timeout=300)
    T.check(status == 0 and 'finished at step %d' % STEPS in text(log) and 'at step %d,' % k2 in text(log),
            'job 3 continues from step %d to the end (status %d)' % (k2, status))
    T.check(lines(os.path.join(d, 'cancelled')) == ['1003'] and 'the run is done' in text(os.path.join(d, 'job-1002.out')),
            'job 3 says the run is done and cancels its successor (%s)' % lines(os.path.join(d, 'cancelled')))

    # 4. the chain's result is the uninterrupted run's
    T.compare_h5(os.path.join(ref, 'out', 'checkpoint.h5'), checkpoint, 'chain vs uninterrupted, checkpoint')
    T.compare_h5(os.path.join(ref, 'out', 'series.h5'), os.path.join(d, 'out', 'series.h5'),
                 'chain vs uninterrupted, series', skip=('wall_time',))
finally:
    for q in started:
        if q.poll() is None:
            stop(q)
T.finish()
