"""Reproduce chapter 8 (Table 8.1, Figs. 8.2-8.6); same as `hunting reproduce ch8`.

    python reproducers/ch8.py [--out DIR]
"""
import argparse
import sys
from pathlib import Path

from hunting.reproduce.ch8 import run

if __name__ == "__main__":
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("--out", default="out/ch8")
    sys.exit(run(Path(ap.parse_args().out)))
