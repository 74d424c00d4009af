"""The JCGM 101 Monte Carlo of a study's specifications through Python (issue 34 item 3):
on the IMU example over the navigation-grade sheet each symmetric coverage interval's
half-width is the GUM budget's expanded uncertainty U to its second significant digit (the
linear quantities; docs/verdict.md), the verdict names its rule, and the same seed gives the
same answer."""

import pytest

import ttalloc
from conftest import ROOT

IMU = ROOT / "studies" / "imu-triad-example.toml"
SHEET = ROOT / "studies" / "tolerances" / "three-axis-navigation-grade.toml"
#: the quantities whose GUM interval the Monte Carlo validates on this sheet (the
#: misalignment, dominated by the table's rectangular laws, is not: docs/verdict.md)
VALIDATED = [
    "gx bg_x (bias)",
    "gx gs_xx (g-sensitivity)",
    "ax ba_x (bias)",
    "ax sf_x (scale factor)",
]


def sig2(v: float) -> float:
    return float(f"{v:.2g}")


def test_symmetric_intervals_are_the_budgets_u_to_two_digits():
    study = ttalloc.load_study(IMU)
    gum = study.specification_budgets(SHEET).to_dict()["specifications"]
    mc = study.jcgm101(SHEET, significant_digits=2, seed=3).to_dict()
    assert mc["seed"] == 3
    assert mc["significant_digits"] == 2
    assert mc["rule"].startswith("by Monte Carlo (JCGM 101)")
    specs = mc["specifications"]
    assert [s["quantity"] for s in specs] == [g["quantity"] for g in gum]
    for s, g in zip(specs, gum):
        assert s["stabilized"]
        lo, hi = s["symmetric_interval"]
        assert lo < s["mean"] < hi
        # the rule: the symmetric interval within +-limit
        assert s["meets"] == (max(abs(lo), abs(hi)) <= s["limit"])
        if s["quantity"] in VALIDATED:
            assert s["gum_validated"], s["quantity"]
            assert sig2((hi - lo) / 2) == sig2(g["expanded"]), s["quantity"]
    assert mc["meets"] == all(s["meets"] for s in specs)


def test_the_same_seed_gives_the_same_answer():
    study = ttalloc.load_study(IMU)
    a = study.jcgm101(SHEET, significant_digits=1, seed=11).to_dict()
    b = study.jcgm101(SHEET, significant_digits=1, seed=11).to_dict()
    assert a == b


def test_digits_out_of_range_raise_an_input_error_naming_the_argument():
    study = ttalloc.load_study(IMU)
    with pytest.raises(ttalloc.InputError, match="significant_digits"):
        study.jcgm101(SHEET, significant_digits=7)
