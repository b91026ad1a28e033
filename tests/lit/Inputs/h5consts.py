#!/usr/bin/env python3
"""Checks array constants of an sphc snapshot: h5consts.py FILE.h5 ARRAY NAME CHECK ...

CHECK is '=V' (exactly V), '<V' or '>V'. Each constant is the attribute NAME of the group
/ARRAY/constants (its first value). Exits 1 naming every failed check (or a missing
constant), 0 when all hold."""
import re
import subprocess
import sys


def constant(path, array, name):
    """The first value of /ARRAY/constants/NAME (h5dump, as the other scripts; no h5py)."""
    r = subprocess.run(['h5dump', '-m', '%.17g', '-a', f'/{array}/constants/{name}', path],
                       capture_output=True, text=True)
    m = re.search(r'\(0\):\s*([-+0-9.eEinfa]+)', r.stdout)
    return float(m.group(1)) if r.returncode == 0 and m else None


def main(argv):
    if len(argv) < 5 or (len(argv) - 3) % 2:
        print(__doc__, file=sys.stderr)
        return 2
    path, array = argv[1], argv[2]
    bad = 0
    for name, check in zip(argv[3::2], argv[4::2]):
        value = constant(path, array, name)
        if value is None:
            print(f'{path}: no constant /{array}/constants/{name}', file=sys.stderr)
            bad += 1
            continue
        op, want = check[0], float(check[1:])
        ok = value == want if op == '=' else value < want if op == '<' else value > want
        print(f'{array}.{name} = {value!r} ({check}): {"ok" if ok else "FAILED"}')
        bad += not ok
    return 1 if bad else 0


if __name__ == '__main__':
    sys.exit(main(sys.argv))
