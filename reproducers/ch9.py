"""Reproduce chapter 9 (Tables 9.2-9.4, Figs. 9.4-9.8, 11.1, 11.3); same as `hunting reproduce ch9`.

    python reproducers/ch9.py [--out DIR]
"""
import argparse
import sys
from pathlib import Path

from hunting.reproduce.ch9 import run

if __name__ == "__main__":
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("--out", default="out/ch9")
    sys.exit(run(Path(ap.parse_args().out)))
