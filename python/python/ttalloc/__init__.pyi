"""Type stubs of `ttalloc` (checked against the built module by tests/test_stubs.py)."""

from os import PathLike
from typing import Any, Optional, Sequence, Union

import numpy as np
import numpy.typing as npt

_Path = Union[str, "PathLike[str]"]

class InputError(ValueError):
    """The input is wrong: the message names where (a file and key, a keyword argument) and why."""

class Answer:
    """The answer to one question; its keys are the command line's `--json` keys."""

    @property
    def question(self) -> str: ...
    def to_dict(self) -> dict[str, Any]: ...
    def keys(self) -> list[str]: ...
    def __getitem__(self, key: str) -> Any: ...
    def __contains__(self, key: str) -> bool: ...

class Study:
    """A validated study, from a file (`load_study`) or a dict (`Study.from_dict`)."""

    @staticmethod
    def from_dict(d: dict[str, Any]) -> Study: ...
    @property
    def name(self) -> str: ...
    @property
    def path(self) -> str: ...
    @property
    def outputs(self) -> list[str]: ...
    def requirement(self) -> Answer: ...
    def allocate(self, safety_margin: float = 0.0) -> Answer: ...
    def end_to_end(
        self,
        samples: Optional[int] = None,
        seed: Optional[int] = None,
        yield_fraction: Optional[float] = None,
    ) -> Answer: ...
    def check_turntable(
        self,
        tolerances: _Path,
        samples: Optional[int] = None,
        seed: Optional[int] = None,
    ) -> Answer: ...
    def specification_budgets(self, tolerances: _Path) -> Answer: ...
    def jcgm101(
        self,
        tolerances: _Path,
        significant_digits: int = 2,
        seed: Optional[int] = None,
    ) -> Answer: ...
    def estimable(self, tolerances: Optional[_Path] = None) -> Answer: ...
    def monte_carlo(
        self,
        samples: Optional[int] = None,
        seed: Optional[int] = None,
    ) -> Answer: ...
    def design_schedule(
        self,
        positions: Optional[int] = None,
        step_deg: Optional[float] = None,
        seed: Optional[int] = None,
        time_budget_s: Optional[float] = None,
        rates_deg_per_s: Optional[Sequence[float]] = None,
    ) -> Answer: ...
    def report(
        self,
        tolerances: Optional[_Path] = None,
        samples: Optional[int] = None,
        seed: Optional[int] = None,
    ) -> dict[str, bytes]: ...

class AllanResult:
    """The overlapping Allan deviation of a log and its fitted noise (IEEE 952)."""

    @property
    def tau_s(self) -> npt.NDArray[np.float64]: ...
    @property
    def adev(self) -> npt.NDArray[np.float64]: ...
    @property
    def lower(self) -> npt.NDArray[np.float64]: ...
    @property
    def upper(self) -> npt.NDArray[np.float64]: ...
    @property
    def samples(self) -> int: ...
    @property
    def rate_hz(self) -> float: ...
    @property
    def white_noise_per_sqrt_hz(self) -> float: ...
    @property
    def bias_instability(self) -> float: ...
    def to_dict(self) -> dict[str, Any]: ...

def load_study(path: _Path) -> Study: ...
def calibrate(
    study: Study,
    recording: Any,
    specs: Optional[dict[str, float]] = None,
    robust: bool = False,
) -> Answer: ...
def allan(samples: npt.NDArray[np.float64], rate_hz: float) -> AllanResult: ...
