#!/usr/bin/env python3
"""Checks the lid-driven cavity with GTVF (examples/cavity_gtvf.sph) against Ghia, Ghia &
Shin (1982): the checks, error figures and tolerances of cavity.py (see its documentation),
which this runs. Usage: cavity_gtvf.py OUTPUT_DIR [cavity.py options]
"""
import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import cavity  # noqa: E402

if __name__ == "__main__":
    sys.exit(cavity.main())
