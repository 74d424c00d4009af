"""The questions bound after the first round (estimable, Monte Carlo, calibrate) through
Python: the same golden values as tt-lab's Rust tests of the same studies."""

import io
import json

import numpy as np
import pytest

import ttalloc
from conftest import ROOT, TABLE4_SHEET

SIX_FACE = ROOT / "calib-run" / "studies" / "imu-six-face-three-rotation.toml"


def test_estimable_on_the_paper_study_finds_the_five_groups(paper):
    # tt-lab/tests/questions.rs, estimable_on_the_paper_study_finds_the_five_groups
    v = paper.estimable(TABLE4_SHEET).to_dict()
    assert v["reading"] == "actual/beta1/printed"
    assert v["rank"] == 19
    assert v["columns"] == 22
    assert v["table_rank"] == 5
    assert len(v["estimable"]) == 5
    assert v["allocation"]["joint"]["no_bound_needed"] is True
    assert v["allocation"]["ordinary"]["no_bound_needed"] is False


def test_monte_carlo_follows_the_study_and_its_seed(paper):
    # tt-lab/tests/plan_questions.rs, monte_carlo_follows_the_study_and_its_seed
    a = paper.monte_carlo().to_dict()
    assert a["samples"] == 10_000
    assert a["seed"] == 2017
    assert a["bounds"] == "two-step"
    one = paper.monte_carlo(samples=10_000, seed=7).to_dict()
    two = paper.monte_carlo(samples=10_000, seed=7).to_dict()
    assert one["seed"] == 7
    assert one["worst"] == two["worst"]
    assert one["worst"] != a["worst"]


def simulated_recording(study: ttalloc.Study) -> dict:
    """The six-face recording tt-lab's Rust test calibrates (50 Hz, 10 s dwell, seed 4), as a
    dict of column name to array."""
    text = ttalloc._native._simulate_recording(study, 50.0, 10.0, 4)
    header = text.split("\n", 1)[0].split(",")
    data = np.loadtxt(io.StringIO(text), delimiter=",", skiprows=1)
    return {name: np.ascontiguousarray(data[:, j]) for j, name in enumerate(header)}


def test_calibrate_judges_a_simulated_recording():
    # tt-lab/tests/plan_questions.rs, calibrate_judges_a_simulated_recording: nine segments,
    # the caller's specification judged under the ILAC-G8 rule.
    s = ttalloc.load_study(SIX_FACE)
    a = ttalloc.calibrate(s, simulated_recording(s), specs={"bg_x": 100.0}).to_dict()
    assert len(a["run"]["segments"]) == 9
    last = a["verdicts"][-1]
    assert last["meets"] is True
    assert "ILAC-G8" in last["rule"]


def test_calibrate_reads_a_dataframe_as_its_dict():
    pd = pytest.importorskip("pandas")
    s = ttalloc.load_study(SIX_FACE)
    rec = simulated_recording(s)
    assert (
        ttalloc.calibrate(s, pd.DataFrame(rec)).to_dict()
        == ttalloc.calibrate(s, rec).to_dict()
    )


def test_calibrate_names_the_short_column():
    s = ttalloc.load_study(SIX_FACE)
    rec = simulated_recording(s)
    name = list(rec)[1]
    rec[name] = rec[name][:-1]
    with pytest.raises(ttalloc.InputError, match=f"column `{name}`"):
        ttalloc.calibrate(s, rec)


def test_allocate_on_a_rate_study_gives_the_rate_tolerances_like_end_to_end():
    # ttalloc/tests/rate_steps.rs, allocate_shows_the_rate_tolerances_like_end_to_end: the
    # same computation on the same study, rounding only.
    same_path_rel = 1e-12
    s = ttalloc.load_study(ROOT / "studies" / "tactical-rate-table-example.toml")
    a = s.allocate().to_dict()
    e = s.end_to_end(samples=2000).to_dict()
    assert a["two_step_allocation"].startswith("not made: ")
    for key in ("objective", "allocation_arcmin", "certificate", "equal_effects_arcmin"):
        assert key not in a
    assert a["rate_allocation"]["objective_arcmin"] == pytest.approx(
        e["rate_allocation"]["objective_arcmin"], rel=same_path_rel
    )
    assert a["rate_allocation"]["tolerances"] == e["rate_allocation"]["tolerances"]


def test_design_schedule_on_the_three_axis_example_is_no_worse_than_its_schedule():
    # tt-lab/tests/design_questions.rs: on the 45 deg grid (512 candidates) the three-axis
    # example's 32 positions are designed within the condition bound and no worse than its own
    s = ttalloc.load_study(ROOT / "studies" / "three-axis-example.toml")
    v = s.design_schedule(step_deg=45.0).to_dict()
    assert v["candidates"] == 512
    assert v["positions"] == 32
    for k in ("designed", "study", "d_optimal"):
        assert len(v[k]["positions_deg"]) == 32
    assert v["designed"]["objective"] <= v["study"]["objective"]
    assert all(c <= v["max_condition"] for c in v["designed"]["condition_numbers"].values())
    assert v.get("budget") is None and v.get("rates") is None


def test_design_schedule_refuses_a_rate_for_a_study_without_rate_steps(paper):
    with pytest.raises(ttalloc.InputError, match="rates-deg-per-s"):
        paper.design_schedule(rates_deg_per_s=[30.0])


def test_report_is_computed_in_memory_with_its_files(paper):
    # the report's files as `ttalloc report` writes them (tt-report/tests/report_library.rs):
    # report.md, the self-contained report.html, results.json; nothing written to disk
    files = paper.report(samples=2000, seed=5)
    assert {"report.md", "report.html", "results.json"} <= set(files)
    assert all(isinstance(b, bytes) for b in files.values())
    assert any(name.endswith(".svg") for name in files)
    md = files["report.md"].decode()
    assert md.startswith("# ")
    results = json.loads(files["results.json"])
    assert results["seed"] == 5


def test_report_with_too_few_samples_names_the_flag(paper):
    with pytest.raises(ttalloc.InputError, match="samples"):
        paper.report(samples=10)
