"""Bad input raises ttalloc.InputError (a ValueError) naming the key as the command line does;
never a panic (pyo3's PanicException is not a ValueError), never a half answer."""

import tomllib

import numpy as np
import pytest

import ttalloc
from conftest import PAPER_STUDY, TABLE4_SHEET


def paper_dict() -> dict:
    with open(PAPER_STUDY, "rb") as f:
        return tomllib.load(f)


def test_input_error_is_a_value_error():
    assert issubclass(ttalloc.InputError, ValueError)


def test_study_dict_is_the_same_study_as_its_file(paper):
    s = ttalloc.Study.from_dict(paper_dict())
    assert s.name == paper.name
    assert s.path == "<study dict>"
    assert s.requirement()["orientation_requirement_deg"] == (
        paper.requirement()["orientation_requirement_deg"]
    )


def test_study_dict_with_an_unknown_key_is_refused_naming_it():
    d = paper_dict()
    d["site"]["altitude_m"] = 150.0
    with pytest.raises(ttalloc.InputError, match="unknown field `altitude_m`"):
        ttalloc.Study.from_dict(d)
    d = paper_dict()
    d["colour"] = "blue"
    with pytest.raises(ttalloc.InputError, match="unknown field `colour`"):
        ttalloc.Study.from_dict(d)


def test_study_dict_value_out_of_range_names_the_key():
    d = paper_dict()
    d["site"]["latitude_deg"] = 200.0
    with pytest.raises(ttalloc.InputError) as e:
        ttalloc.Study.from_dict(d)
    assert str(e.value).startswith("<study dict>: key `site.latitude_deg`: must lie in")


def test_study_dict_value_without_a_toml_form_names_the_key():
    d = paper_dict()
    d["site"]["latitude_deg"] = None
    with pytest.raises(ttalloc.InputError, match=r"key `site\.latitude_deg`: None"):
        ttalloc.Study.from_dict(d)


def test_study_file_error_names_the_file_and_key(tmp_path):
    text = PAPER_STUDY.read_text().replace("latitude_deg = ", "latitude_deg = 200 #", 1)
    bad = tmp_path / "bad.toml"
    bad.write_text(text)
    with pytest.raises(ttalloc.InputError) as e:
        ttalloc.load_study(bad)
    assert str(e.value).startswith(f"{bad}: key `site.latitude_deg`: must lie in")


def test_missing_files_name_the_path(paper, tmp_path):
    with pytest.raises(ttalloc.InputError, match="nowhere.toml"):
        ttalloc.load_study(tmp_path / "nowhere.toml")
    with pytest.raises(ttalloc.InputError, match="no-sheet.toml"):
        paper.check_turntable(tmp_path / "no-sheet.toml")


def test_bad_keyword_values_name_the_command_line_flag(paper):
    # the command line's location of the same value (tt-lab's one rule): its flag
    with pytest.raises(ttalloc.InputError, match="^--samples: "):
        paper.check_turntable(TABLE4_SHEET, samples=0)
    with pytest.raises(ttalloc.InputError, match="^--safety-margin: "):
        paper.allocate(safety_margin=1.5)


def test_allan_refuses_what_it_cannot_read_in_place():
    x = np.zeros(1000)
    with pytest.raises(ttalloc.InputError, match="^samples: the array is not contiguous"):
        ttalloc.allan(x[::2], 100.0)
    with pytest.raises(ttalloc.InputError, match="^samples: not a 1-D float64"):
        ttalloc.allan(x.astype(np.float32), 100.0)
    with pytest.raises(ttalloc.InputError, match="^samples: not a 1-D float64"):
        ttalloc.allan([0.0] * 1000, 100.0)
    with pytest.raises(ttalloc.InputError, match="^rate_hz: "):
        ttalloc.allan(x, -1.0)
    with pytest.raises(ttalloc.InputError, match="^samples: "):
        ttalloc.allan(np.array([1.0, np.nan, 2.0, 3.0]), 100.0)
    with pytest.raises(ttalloc.InputError, match="^samples: "):
        ttalloc.allan(np.zeros(2), 100.0)
