"""Turntable error allocation for sensor calibration, from Python.

The native module (`ttalloc._native`, Rust through pyo3) answers each study-level question;
this package re-exports it. See docs/python.md.
"""

from ttalloc._native import (
    AllanResult,
    Answer,
    InputError,
    Study,
    allan,
    calibrate,
    load_study,
)

__all__ = [
    "AllanResult",
    "Answer",
    "InputError",
    "Study",
    "allan",
    "calibrate",
    "load_study",
]
