# lit configuration shared by the .sph test suites of sphc: tests/lit (one file per pass,
# --report, --emit) and tests/errors (one file per diagnostic). CMake writes one
# lit.site.cfg.py per suite (from lit.site.cfg.py.in) that sets the paths below and loads this.
import os

import lit.formats

config.name = 'sphc-' + os.path.basename(config.test_source_root)
config.test_format = lit.formats.ShTest(execute_external=False)
config.suffixes = ['.sph']
# Inputs/: files that tests import or read, not tests themselves.
config.excludes = ['Inputs']

# A tool name as a whole word of a RUN line (not part of a path, an option or another word).
def tool(name):
    return r'(?<![\w%/.-])' + name + r'(?![\w.-])'

config.substitutions.append(('%sphc', os.path.join(config.sphc_bin_dir, 'sphc')))
# The build tree (tests of `cmake --install`). A lit.site.cfg.py written before
# sphc_build_dir existed: the build tree is the parent of its bin/.
config.substitutions.append(('%build_dir', getattr(config, 'sphc_build_dir', None) or
                             os.path.dirname(config.sphc_bin_dir)))
config.substitutions.append((tool('FileCheck'), config.filecheck))
config.substitutions.append((tool('not'), config.not_tool))

# Tests run in a clean environment except for what sphc needs to find a C++ compiler.
for var in ('PATH', 'HOME', 'TMPDIR'):
    if var in os.environ:
        config.environment[var] = os.environ[var]

# `REQUIRES: opencl`: the build found OpenCL (buildinfo.txt has a non-empty opencl_libs, and
# libsphc_runtime_ocl.a was built), so --backend=opencl solvers can be built and run.
_build_dir = getattr(config, 'sphc_build_dir', None) or os.path.dirname(config.sphc_bin_dir)
_buildinfo = os.path.join(_build_dir, 'share', 'sphc', 'buildinfo.txt')
if os.path.exists(_buildinfo):
    with open(_buildinfo) as f:
        _info = dict(l.rstrip('\n').split('=', 1) for l in f if '=' in l)
    if _info.get('opencl_libs', '').strip():
        config.available_features.add('opencl')
# Helper scripts of the tests (tests/lit/Inputs), e.g. %h5close A.h5 B.h5 --rtol R.
config.substitutions.append(('%h5close', 'python3 ' + os.path.join(
    config.sphc_src_root, 'tests', 'lit', 'Inputs', 'h5close.py')))
# %h5range FILE.h5 DATASET LO HI ...: every value within [LO, HI] (tests/lit/Inputs/h5range.py).
config.substitutions.append(('%h5range', 'python3 ' + os.path.join(
    config.sphc_src_root, 'tests', 'lit', 'Inputs', 'h5range.py')))
# %precision_compare DOUBLE.h5 SINGLE.h5 --id ... --rtol R: a single-precision run against the
# double one (tests/lit/Inputs/precision_compare.py).
config.substitutions.append(('%precision_compare', 'python3 ' + os.path.join(
    config.sphc_src_root, 'tests', 'lit', 'Inputs', 'precision_compare.py')))
# %h5consts FILE.h5 ARRAY NAME CHECK ...: array constants against exact values or bounds
# ('=V', '<V', '>V'; tests/lit/Inputs/h5consts.py).
config.substitutions.append(('%h5consts', 'python3 ' + os.path.join(
    config.sphc_src_root, 'tests', 'lit', 'Inputs', 'h5consts.py')))
import subprocess as _sp

# The first Python here that imports `modules` (python3 on PATH, then /usr/bin/python3), or None.
def _python_with(modules):
    for py in ('python3', '/usr/bin/python3'):
        try:
            if _sp.run([py, '-c', 'import ' + modules], stdout=_sp.DEVNULL,
                       stderr=_sp.DEVNULL).returncode == 0:
                return py
        except OSError:
            pass
    return None

# `REQUIRES: pysph`: a Python here imports PySPH (Debian python3-pysph), for the tests of
# `sphc study --pysph` and the live PySPH comparisons; %pysph_python is that Python.
_py = _python_with('pysph')
if _py:
    config.available_features.add('pysph')
    config.substitutions.append(('%pysph_python', _py))
# `REQUIRES: h5py`: a Python here imports h5py and numpy (Debian python3-h5py, installed by
# scripts/setup-deps.sh; the PySPH comparisons in tests/lit/ported read snapshots with it);
# %h5py_python is that Python, and
# %restart_bitwise UNINTERRUPTED_DIR RESTARTED_DIR checks that every file of a restarted run is
# bitwise the uninterrupted run's (tests/lit/Inputs/restart_bitwise.py).
_py = _python_with('h5py, numpy')
if _py:
    config.available_features.add('h5py')
    config.substitutions.append(('%h5py_python', _py))
    config.substitutions.append(('%restart_bitwise', _py + ' ' + os.path.join(
        config.sphc_src_root, 'tests', 'lit', 'Inputs', 'restart_bitwise.py')))
# `REQUIRES: matplotlib`: a Python here imports matplotlib, so `sphc study` (which looks for
# it among the same two, compiler/driver/Study.cpp) draws its plots.
if _python_with('matplotlib'):
    config.available_features.add('matplotlib')
# `REQUIRES: avx512vbmi2`: this CPU has AVX-512 F and VBMI2 (/proc/cpuinfo), so a solver
# built -march=native takes the --cluster-queue form (its #if), for the tests that look at
# that form's instructions (objdump).
try:
    with open('/proc/cpuinfo') as _f:
        _flags = next((l.split(':', 1)[1].split() for l in _f if l.startswith('flags')), [])
    if 'avx512f' in _flags and 'avx512_vbmi2' in _flags:
        config.available_features.add('avx512vbmi2')
except OSError:
    pass
