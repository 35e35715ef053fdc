"""Invariant: the sources keep the layout of doc/DESIGN.md "Source layout": every file under
src/kernels/ is pure (no PETSc, MPI, HDF5, FFTW, C binding or include, and no use of a module
outside the kernels), each folder imports only from the folders it may (scripts/pure-modules
IMPORTS), module mod_x lives in x.F90. make runs the same check before it compiles; this test also
shows that the check catches what it must: on a copy of the sources it plants, one at a time, a
kernel that uses hdf5, a kernel that uses mod_errors (runtime), a fluid module that uses
mod_fictitious_domain (bodies), a C source among the kernels and a module in a file of another
name, and each must fail the check with one violation, named by file, line and import.
Also the naming rule of the particle glue modules (doc/DESIGN.md "Names of the particle glue
modules"): every public name of mod_x in src/bodies/ and in the kernels particle_system,
particle_contacts, particle_lubrication and lubrication_dynamics is x_t or x_<verb>.
Exact (no tolerance): exit statuses and message text. Python standard library only; ~2 s of CPU."""
import os
import re
import shutil
import subprocess
import sys
import tempfile

from checks import check, finish

ROOT = os.environ.get('FDSUSP_ROOT') or os.path.abspath(os.path.join(os.path.dirname(__file__), '..', '..'))
SCRIPT = os.path.join(ROOT, 'scripts', 'pure-modules')


def run_check(root):
    p = subprocess.run([sys.executable, SCRIPT, '--check', root], capture_output=True, text=True, timeout=60)
    return p.returncode, p.stderr


rc, err = run_check(ROOT)
check(rc == 0 and err == '', 'the checkout keeps the layout (exit %d%s)' % (rc, (': ' + err.strip()) if err else ''))

# every kernel is pure by the transitive analysis too (what the unit tests link)
kernels = sorted(os.path.join('src', 'kernels', f) for f in os.listdir(os.path.join(ROOT, 'src', 'kernels'))
                 if f.endswith('.F90'))
p = subprocess.run([sys.executable, SCRIPT] + kernels, cwd=ROOT, capture_output=True, text=True, timeout=60)
pure = p.stdout.split()
check(p.returncode == 0 and pure == kernels, 'scripts/pure-modules lists all %d kernels as pure (%s)'
      % (len(kernels), ', '.join(sorted(set(kernels) - set(pure))) or 'none missing'))

# the naming rule of the particle glue modules
glue = sorted(os.path.join('src', 'bodies', f) for f in os.listdir(os.path.join(ROOT, 'src', 'bodies'))
              if f.endswith('.F90')) + \
       [os.path.join('src', 'kernels', f + '.F90') for f in ('particle_system', 'particle_contacts',
                                                             'particle_lubrication', 'lubrication_dynamics')]
for path in glue:
    short = os.path.basename(path)[:-len('.F90')]
    text = open(os.path.join(ROOT, path)).read().replace('&\n', ' ')
    names = [n.strip() for m in re.finditer(r'^\s*public\s*::(.*)$', text, re.M) for n in m.group(1).split(',')]
    off = [n for n in names if not n.startswith(short + '_')]
    check(names and not off, '%s: its %d public names are %s_t or %s_<verb>%s'
          % (path, len(names), short, short, ' (not: %s)' % ', '.join(off) if off else ''))


def planted(what, path, edit, expect):
    """Copy the sources, apply edit(text) to path, and expect the check to fail naming it."""
    with tempfile.TemporaryDirectory() as tmp:
        for d in ('src', 'ref', os.path.join('tests', 'unit')):
            shutil.copytree(os.path.join(ROOT, d), os.path.join(tmp, d),
                            ignore=shutil.ignore_patterns('*.o', '*.mod'))
        target = os.path.join(tmp, path)
        if edit is None:                      # a new file
            open(target, 'w').write(expect[1])
            expect = expect[0]
        else:
            text = edit(open(target).read())
            open(target, 'w').write(text)
        rc, err = run_check(tmp)
    expect = expect + ['layout: 1 violation(s)']      # that one, and nothing else broken by the edit
    check(rc == 1 and all(e in err for e in expect),
          '%s: the check fails (exit %d) naming %s%s' % (what, rc, ' and '.join(repr(e) for e in expect),
                                                        '' if rc == 1 and all(e in err for e in expect)
                                                        else ' (got: %s)' % err.strip()))


def after_module(line):
    """Insert a line after the module statement."""
    def edit(text):
        head, sep, tail = text.partition('\nmodule ')
        first, nl, rest = tail.partition('\n')
        return head + sep + first + nl + line + '\n' + rest
    return edit


planted('a kernel that uses hdf5', 'src/kernels/contact.F90', after_module('  use hdf5'),
        ['src/kernels/contact.F90:', 'use hdf5', 'HDF5', 'must be pure'])
planted('a kernel that uses mod_errors', 'src/kernels/contact.F90', after_module('  use mod_errors, only: is_root'),
        ['src/kernels/contact.F90:', 'use mod_errors', 'src/runtime/errors.F90',
         'src/kernels/ may import only src/kernels/'])
planted('a kernel that binds to C', 'src/kernels/vector.F90',
        lambda t: t.replace('contains', 'contains\n  subroutine c_side() bind(C, name="c_side")\n  end subroutine c_side', 1),
        ['src/kernels/vector.F90:', 'bind(C', 'C binding'])
planted('the fluid importing the bodies', 'src/fluid/fluid.F90', after_module('  use mod_fictitious_domain'),
        ['src/fluid/fluid.F90:', 'use mod_fictitious_domain', 'src/bodies/fictitious_domain.F90',
         'src/fluid/ may import only'])
planted('a unit test importing the runtime', 'tests/unit/test_contact.F90',
        lambda t: t.replace('  implicit none', '  use mod_errors, only: is_root\n  implicit none', 1),
        ['tests/unit/test_contact.F90:', 'use mod_errors', 'tests/unit/ may import only'])
planted('a C source among the kernels', 'src/kernels/fast.c', None,
        (['src/kernels/fast.c', 'C source', 'must be pure'], 'int fast(void) { return 0; }\n'))
planted('a module in a file of another name', 'src/kernels/helpers.F90', None,
        (['src/kernels/helpers.F90', 'must hold exactly the module mod_helpers'],
         'module mod_tools\n  implicit none\nend module mod_tools\n'))
planted('a source outside the folders', 'src/loose.F90', None,
        (['src/loose.F90', 'not in a folder of the layout'], 'module mod_loose\n  implicit none\nend module mod_loose\n'))
finish()
