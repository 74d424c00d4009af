"""The cost of the Python layer: `ttalloc.allan` on a 1e7-sample array and the vendor check of
the IMU example, each against the Rust library call alone timed in the same run (inside the
native module, on the same inputs, no conversion). Interleaved rounds (alternating
which call goes first), best of each. The library's time of the vendor check is
`tt_lab::vendor::check` alone; the Python call adds its JSON view and the conversion.

Run from the repository's root with the wheel installed (release build):
    python python/bench/bench_allan.py [SAMPLES] [ROUNDS]
"""

import sys
import time

import numpy as np

import ttalloc
from ttalloc import _native

SAMPLES = int(float(sys.argv[1])) if len(sys.argv) > 1 else 10_000_000
ROUNDS = int(sys.argv[2]) if len(sys.argv) > 2 else 5
RATE_HZ = 100.0
STUDY = "studies/imu-triad-example.toml"
SHEET = "studies/tolerances/three-axis-navigation-grade.toml"


def best(f, rounds):
    return min(f() for _ in range(rounds))


def timed(f):
    def run():
        t0 = time.perf_counter()
        f()
        return time.perf_counter() - t0

    return run


def main():
    y = np.random.default_rng(1).normal(0.0, 0.1, SAMPLES)
    py_allan = []
    rust_allan = []
    for r in range(ROUNDS):
        # alternate which goes first (the first call of a round pays for cold caches)
        if r % 2:
            rust_allan.append(_native._library_seconds_allan(y, RATE_HZ))
        py_allan.append(timed(lambda: ttalloc.allan(y, RATE_HZ))())
        if not r % 2:
            rust_allan.append(_native._library_seconds_allan(y, RATE_HZ))
    study = ttalloc.load_study(STUDY)
    py_check = []
    rust_check = []
    for r in range(ROUNDS):
        if r % 2:
            rust_check.append(_native._library_seconds_check_turntable(study, SHEET))
        py_check.append(timed(lambda: study.check_turntable(SHEET).to_dict())())
        if not r % 2:
            rust_check.append(_native._library_seconds_check_turntable(study, SHEET))
    a, ra = min(py_allan), min(rust_allan)
    c, rc = min(py_check), min(rust_check)
    print(f"allan, {SAMPLES:.0e} samples at {RATE_HZ:g} Hz: Python {a:.3f} s, library {ra:.3f} s, ratio {a / ra:.3f}")
    print(f"check_turntable, {STUDY} with {SHEET}: Python (to_dict included) {c:.3f} s, library {rc:.3f} s, ratio {c / rc:.3f}")


if __name__ == "__main__":
    main()
