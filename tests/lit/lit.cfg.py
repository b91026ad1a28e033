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
