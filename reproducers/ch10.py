"""Reproduce chapter 9 (Figs. 10.4-10.12 on the virtual LiMMS); same as `hunting reproduce ch10`.

    python reproducers/ch10.py [--out DIR]
"""
import argparse
import sys
from pathlib import Path

from hunting.reproduce.ch10 import run

if __name__ == "__main__":
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("--out", default="out/ch10")
    sys.exit(run(Path(ap.parse_args().out)))
