#!/usr/bin/env python3
"""Tests the plot of a validation check (tests/validation/plots.py) on a small run.

Run by run_case.sh as the check of a small elliptical drop (CASE elliptical_drop:plot_test,
tests/validation/CMakeLists.txt), so OUTPUT_DIR holds real snapshots. With the interpreter
run_case.sh chose (the one the checks run with), it runs elliptical_drop.py on them

  1. without --plot: the check passes and writes OUTPUT_DIR/elliptical_drop.png, which must
     be a PNG: the 8-byte signature, an IHDR chunk of nonzero width and height with a valid
     CRC, IDAT data that inflates to height rows of the stated size and is not one flat
     colour (more than 10 distinct byte values), and an IEND chunk at the end;
  2. with --plot PATH: the same PNG at PATH;
  3. with matplotlib made unimportable (a stub package on PYTHONPATH that raises
     ImportError): the check still passes, says the plot was skipped, and writes nothing;
  4. with --plot '': the check passes and writes no plot.

Exits 0 when all of these hold, 1 otherwise.

Usage: plot_test.py OUTPUT_DIR [--plot IGNORED] (run_case.sh passes --plot; this test
chooses its own paths)
"""
import os
import struct
import subprocess
import sys
import tempfile
import zlib

from snapshots import report_failures  # tests/validation/snapshots.py

HERE = os.path.dirname(os.path.abspath(__file__))
CHECK = os.path.join(HERE, "elliptical_drop.py")
SIGNATURE = b"\x89PNG\r\n\x1a\n"


def png_problems(path):
    """What is wrong with the PNG file at `path` (empty list: nothing)."""
    if not os.path.isfile(path):
        return ["%s was not written" % path]
    data = open(path, "rb").read()
    if len(data) == 0:
        return ["%s is empty" % path]
    if not data.startswith(SIGNATURE):
        return ["%s does not start with the PNG signature: %r" % (path, data[:8])]
    chunks = []
    pos = len(SIGNATURE)
    while pos + 8 <= len(data):
        length, kind = struct.unpack(">I4s", data[pos:pos + 8])
        body = data[pos + 8:pos + 8 + length]
        crc = data[pos + 8 + length:pos + 12 + length]
        if len(body) != length or len(crc) != 4:
            return ["%s: chunk %r truncated" % (path, kind)]
        if struct.unpack(">I", crc)[0] != zlib.crc32(kind + body) & 0xffffffff:
            return ["%s: chunk %r has a bad CRC" % (path, kind)]
        chunks.append((kind, body))
        pos += 12 + length
    if not chunks or chunks[0][0] != b"IHDR" or len(chunks[0][1]) != 13:
        return ["%s: the first chunk is not an IHDR" % path]
    if chunks[-1][0] != b"IEND" or pos != len(data):
        return ["%s: no IEND chunk at the end" % path]
    width, height, depth, colour = struct.unpack(">IIBB", chunks[0][1][:10])
    if width == 0 or height == 0:
        return ["%s: %d x %d pixels" % (path, width, height)]
    channels = {0: 1, 2: 3, 3: 1, 4: 2, 6: 4}.get(colour)
    if channels is None or depth != 8:
        return ["%s: unexpected colour type %d, depth %d" % (path, colour, depth)]
    raw = zlib.decompress(b"".join(b for k, b in chunks if k == b"IDAT"))
    if len(raw) != height * (1 + width * channels):
        return ["%s: %d bytes of pixel data for %d x %d x %d"
                % (path, len(raw), width, height, channels)]
    if len(set(raw)) <= 10:
        return ["%s: the image is (nearly) one flat colour" % path]
    print("  %s: PNG, %d x %d pixels, %d bytes" % (path, width, height, len(data)))
    return []


def run_check(outdir, args, env=None):
    """(exit status, stdout) of the check on outdir."""
    cmd = [sys.executable, CHECK, outdir] + args
    print("$ " + " ".join(cmd))
    p = subprocess.run(cmd, stdout=subprocess.PIPE, stderr=subprocess.STDOUT,
                       universal_newlines=True, env=env)
    for line in p.stdout.splitlines():
        if line.startswith(("plot ", "PASSED", "FAILED")):
            print("  " + line)
    return p.returncode, p.stdout


def main():
    if len(sys.argv) < 2 or not os.path.isdir(sys.argv[1]):
        sys.stderr.write("usage: plot_test.py OUTPUT_DIR [--plot IGNORED]\n")
        return 2
    outdir = sys.argv[1]
    failures = []

    default = os.path.join(outdir, "elliptical_drop.png")
    if os.path.exists(default):
        os.remove(default)
    rc, out = run_check(outdir, [])
    if rc != 0:
        failures.append("1. the check failed (exit %d) on the small run:\n%s" % (rc, out))
    failures += ["1. " + m for m in png_problems(default)]

    explicit = os.path.join(outdir, "explicit.png")
    rc, out = run_check(outdir, ["--plot", explicit])
    if rc != 0:
        failures.append("2. the check failed (exit %d) with --plot" % rc)
    failures += ["2. " + m for m in png_problems(explicit)]

    with tempfile.TemporaryDirectory() as stub:
        os.mkdir(os.path.join(stub, "matplotlib"))
        with open(os.path.join(stub, "matplotlib", "__init__.py"), "w") as f:
            f.write("raise ImportError('matplotlib hidden by plot_test.py')\n")
        env = dict(os.environ)
        env["PYTHONPATH"] = stub + os.pathsep + env.get("PYTHONPATH", "")
        skipped = os.path.join(outdir, "skipped.png")
        rc, out = run_check(outdir, ["--plot", skipped], env=env)
        if rc != 0:
            failures.append("3. without matplotlib the check failed (exit %d):\n%s" % (rc, out))
        if "plot skipped: matplotlib is not available" not in out:
            failures.append("3. without matplotlib the check did not say the plot was skipped")
        if os.path.exists(skipped):
            failures.append("3. without matplotlib %s was written" % skipped)

    os.remove(default)
    rc, out = run_check(outdir, ["--plot", ""])
    if rc != 0:
        failures.append("4. the check failed (exit %d) with --plot ''" % rc)
    if os.path.exists(default):
        failures.append("4. with --plot '' the check wrote %s" % default)

    if report_failures(failures):
        return 1
    print("PASSED: the check writes a valid PNG by default and at --plot PATH, skips the plot "
          "without matplotlib and with --plot '', and passes in every case")
    return 0


if __name__ == "__main__":
    sys.exit(main())
