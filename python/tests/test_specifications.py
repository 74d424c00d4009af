"""The GUM budget and decision of a study's specifications (issue 34) through Python: the IMU
example on the navigation-grade sheet gives docs/verdict.md's figures, the figures
ttalloc/tests/specifications.rs checks against the command line (3 significant digits as
printed)."""

import math

import pytest

import ttalloc
from conftest import ROOT, TABLE4_SHEET

IMU = ROOT / "studies" / "imu-triad-example.toml"
SHEET = ROOT / "studies" / "tolerances" / "three-axis-navigation-grade.toml"
# docs/verdict.md, "The IMU example": quantity, U (95 %), ratio U / limit
GOLDEN = [
    ("gx bg_x (bias)", 1.08, 10.8),
    ("gx gs_xx (g-sensitivity)", 0.822, 8.22),
    ("ax ba_x (bias)", 98.4, 0.984),
    ("ax sf_x (scale factor)", 19.7, 0.655),
    ("ax mis_xy (misalignment)", 8.46, 0.423),
]
#: U = k u_c and ratio = U / limit: the same product computed twice, relative.
SAME_REL = 1e-12


def sig3(v: float) -> float:
    return float(f"{v:.3g}")


def test_imu_examples_budgets_are_the_documented_ones():
    d = ttalloc.load_study(IMU).specification_budgets(SHEET).to_dict()
    specs = d["specifications"]
    assert [s["quantity"] for s in specs] == [g[0] for g in GOLDEN]
    for s, (_, u, ratio) in zip(specs, GOLDEN):
        assert sig3(s["expanded"]) == u
        assert sig3(s["ratio"]) == ratio
        assert s["expanded"] == pytest.approx(
            s["coverage_factor"] * s["combined_standard_uncertainty"], rel=SAME_REL
        )
        assert s["ratio"] == pytest.approx(s["expanded"] / s["limit"], rel=SAME_REL)
        assert s["meets"] == (s["ratio"] <= 1.0)
    assert sum(s["meets"] for s in specs) == 3
    assert d["meets"] is False
    assert "U / limit <= 1" in d["rule"]


def test_check_turntable_carries_the_same_decision():
    study = ttalloc.load_study(IMU)
    check = study.check_turntable(SHEET, samples=2000)
    assert check["decision"] == study.specification_budgets(SHEET).to_dict()


def test_a_study_without_specifications_names_the_accuracy_rule(paper):
    d = paper.specification_budgets(TABLE4_SHEET).to_dict()
    assert d["meets"] is None
    assert d["specifications"] == []
    assert d["rule"]
