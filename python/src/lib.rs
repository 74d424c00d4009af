//! `ttalloc-py`: the Python package `ttalloc` (pyo3, abi3, built by maturin: see
//! `python/README.md`). Each Python function is one Rust function here that converts its
//! arguments, calls the study-level library `tt-lab` and converts its answer's JSON view (the command
//! line's `--json` keys); no science and no view lives here.
//!
//! Errors: an input error raises `ttalloc.InputError` (a `ValueError`) whose message names the
//! location as the command line does (``file: key `x` ``, a keyword argument); anything else
//! raises `RuntimeError`. Long computations release the GIL.

use numpy::{PyArray1, PyArrayMethods};
use pyo3::create_exception;
use pyo3::exceptions::{PyRuntimeError, PyValueError};
use pyo3::prelude::*;
use pyo3::types::{PyBool, PyDict, PyFloat, PyInt, PyList, PyString, PyTuple};
use std::path::PathBuf;
use tt_lab::LabError;

create_exception!(
    ttalloc,
    InputError,
    PyValueError,
    "The input is wrong: the message names where (a file and key, a keyword argument) and why, as the command line does."
);

/// The source name of a study given as a dict (errors and answers name it).
pub const DICT_SOURCE: &str = "<study dict>";

fn to_py(e: LabError) -> PyErr {
    match e.input() {
        Some(i) => InputError::new_err(i.to_string()),
        None => PyRuntimeError::new_err(e.to_string()),
    }
}

/// A tt-lab answer's JSON view (`--json`'s keys) as a JSON value.
fn view<T: serde::Serialize>(v: &T) -> Result<serde_json::Value, LabError> {
    serde_json::to_value(v).map_err(|e| LabError::Library(Box::new(e)))
}

fn vendor_options(samples: Option<u64>, seed: Option<u64>) -> tt_lab::vendor::Options {
    tt_lab::vendor::Options {
        samples,
        seed,
        ..tt_lab::vendor::Options::default()
    }
}

/// `allocate --json` with the full-range constraint: the two-step allocation's view, or for a
/// study with rate steps the rate study's (the two-step allocation not made).
fn allocate(s: &study::Study, safety_margin: f64) -> Result<serde_json::Value, LabError> {
    let form = alloc_opt::ConstraintForm::FullRange;
    let o = tt_lab::allocation::Options {
        form,
        safety_margin,
        tolerances: None,
    };
    let r = tt_lab::allocation::allocate_study(s, &o)?;
    let Some(a) = r.two_step() else {
        let rate = r.rate().and_then(|(e2e, x)| {
            x.as_ref()
                .map(|x| tt_lab::vendor::rate::RateAllocationJson::new(e2e, x))
        });
        return view(&tt_lab::allocation::RateStudyJson {
            study: &s.path,
            two_step_allocation: format!("not made: {}", tt_lab::loaded::STATIC_REQUIREMENT_NOTE),
            extras: tt_lab::json::ExtrasJson {
                rate_allocation: rate,
                ..tt_lab::json::ExtrasJson::default()
            },
        });
    };
    let mut v = tt_lab::allocation::allocate_json(s, a, form, safety_margin)?;
    v.extras.angle_dependent = r
        .angle()
        .map(|(e2e, an)| tt_lab::allocation::angle::AngleDependentJson::new(e2e, an));
    view(&v)
}

/// A JSON answer as Python objects (dicts, lists, floats; `None` for `null`).
fn json_to_py<'py>(py: Python<'py>, v: &serde_json::Value) -> PyResult<Bound<'py, PyAny>> {
    let text = serde_json::to_string(v).map_err(|e| PyRuntimeError::new_err(e.to_string()))?;
    py.import("json")?.call_method1("loads", (text,))
}

/// One Python value of a study dict as TOML (`at`: its key path, for the error).
fn py_to_toml(v: &Bound<'_, PyAny>, at: &str) -> PyResult<toml::Value> {
    let bad = |what: &str| {
        InputError::new_err(format!(
            "{DICT_SOURCE}: key `{at}`: {what} has no form in a study file (give a str, int, float, bool, list or dict)"
        ))
    };
    if v.is_instance_of::<PyBool>() {
        return Ok(toml::Value::Boolean(v.extract()?));
    }
    if v.is_instance_of::<PyInt>() {
        return v
            .extract::<i64>()
            .map(toml::Value::Integer)
            .map_err(|_| bad("an integer beyond 64 bits"));
    }
    if v.is_instance_of::<PyFloat>() {
        return Ok(toml::Value::Float(v.extract()?));
    }
    if v.is_instance_of::<PyString>() {
        return Ok(toml::Value::String(v.extract()?));
    }
    if let Ok(d) = v.cast::<PyDict>() {
        let mut t = toml::Table::new();
        for (k, x) in d.iter() {
            let key: String = k
                .extract()
                .map_err(|_| bad("a dict whose key is not a str"))?;
            let path = if at.is_empty() {
                key.clone()
            } else {
                format!("{at}.{key}")
            };
            t.insert(key, py_to_toml(&x, &path)?);
        }
        return Ok(toml::Value::Table(t));
    }
    if v.is_instance_of::<PyList>() || v.is_instance_of::<PyTuple>() {
        let items = v
            .try_iter()?
            .enumerate()
            .map(|(i, x)| py_to_toml(&x?, &format!("{at}[{i}]")))
            .collect::<PyResult<Vec<_>>>()?;
        return Ok(toml::Value::Array(items));
    }
    if v.is_none() {
        return Err(bad("None"));
    }
    Err(bad(&format!("a {}", v.get_type().name()?)))
}

/// A validated study (turntable, sensor, site, schedule, requirement), from a file
/// (`ttalloc.load_study`) or a dict (`Study.from_dict`).
#[pyclass(frozen, module = "ttalloc")]
pub struct Study {
    inner: study::Study,
}

#[pymethods]
impl Study {
    /// A study from a dict in the study file's schema (the same keys and tables as the TOML
    /// file): refused exactly as the same file would be (an unknown key, a value out of range).
    #[staticmethod]
    fn from_dict(d: &Bound<'_, PyDict>) -> PyResult<Self> {
        let value = py_to_toml(d.as_any(), "")?;
        let text = toml::to_string(&value)
            .map_err(|e| InputError::new_err(format!("{DICT_SOURCE}: not a study table: {e}")))?;
        let inner = study::Study::parse(DICT_SOURCE, &text).map_err(|e| to_py(e.into()))?;
        Ok(Self { inner })
    }

    /// The study's name (`name`).
    #[getter]
    fn name(&self) -> &str {
        &self.inner.name
    }

    /// Where the study came from, as errors and answers name it (the path as given, or
    /// `<study dict>`).
    #[getter]
    fn path(&self) -> &str {
        &self.inner.path
    }

    /// The names of the sensor's calibrated outputs, in study order.
    #[getter]
    fn outputs(&self) -> Vec<String> {
        self.inner
            .calibration
            .outputs()
            .iter()
            .map(|o| o.output().name.clone())
            .collect()
    }

    /// The orientation requirement (eq 15-16): `requirement --json`.
    fn requirement(&self, py: Python<'_>) -> PyResult<Answer> {
        let s = &self.inner;
        let opts = tt_lab::requirement::Options::default();
        Answer::of(
            "requirement",
            py.detach(|| tt_lab::requirement::requirement(s, &opts).and_then(|a| view(&a.view()))),
        )
    }

    /// The two-step allocation (problems 31-34, full-range constraint): `allocate --json`.
    #[pyo3(signature = (safety_margin = 0.0))]
    fn allocate(&self, py: Python<'_>, safety_margin: f64) -> PyResult<Answer> {
        let s = &self.inner;
        Answer::of("allocate", py.detach(|| allocate(s, safety_margin)))
    }

    /// The end-to-end answer per output (the two-step box, the direct and yield-based
    /// allocations, the noise part, per reading): `end-to-end --json`.
    #[pyo3(signature = (samples = None, seed = None, yield_fraction = None))]
    fn end_to_end(
        &self,
        py: Python<'_>,
        samples: Option<u64>,
        seed: Option<u64>,
        yield_fraction: Option<f64>,
    ) -> PyResult<Answer> {
        let s = &self.inner;
        let d = tt_lab::end_to_end::Options::default();
        let o = tt_lab::end_to_end::Options {
            samples,
            seed,
            yield_fraction: yield_fraction.unwrap_or(d.yield_fraction),
            ..d
        };
        Answer::of(
            "end_to_end",
            py.detach(|| {
                let r = tt_lab::end_to_end::end_to_end(s, &o)?;
                view(&tt_lab::end_to_end::EndToEndJson::of(s, &r))
            }),
        )
    }

    /// The vendor check of a tolerance sheet (a TOML file): the verdict per output, the worst
    /// case and the Monte Carlo yield: `check-turntable --json`.
    #[pyo3(signature = (tolerances, samples = None, seed = None))]
    fn check_turntable(
        &self,
        py: Python<'_>,
        tolerances: PathBuf,
        samples: Option<u64>,
        seed: Option<u64>,
    ) -> PyResult<Answer> {
        let s = &self.inner;
        Answer::of(
            "check_turntable",
            py.detach(|| {
                let v = tt_lab::vendor::check(s, &tolerances, &vendor_options(samples, seed))?;
                view(&tt_lab::vendor::CheckJson::of(s, &v))
            }),
        )
    }

    /// The GUM budget and the decision of every specification of the study (issue 34) over a
    /// tolerance sheet's box: `check-turntable --json`'s `decision` (without specifications:
    /// the accuracy rule, `meets` `None`).
    fn specification_budgets(&self, py: Python<'_>, tolerances: PathBuf) -> PyResult<Answer> {
        let s = &self.inner;
        Answer::of(
            "specification_budgets",
            py.detach(|| {
                let sheet = s
                    .load_sheet(&tolerances)
                    .map_err(tt_lab::InputError::from)?;
                let e2e = tt_lab::loaded::simulator(s)?;
                let v = tt_lab::vendor::spec::compute(s, &e2e, sheet.upper_bounds_rad())?;
                view(&tt_lab::vendor::spec::SpecVerdictJson::new(s, v.as_ref()))
            }),
        )
    }

    /// The JCGM 101 Monte Carlo of every specification of the study over a tolerance sheet's
    /// box (issue 34 item 3): per specification the mean, u(y), the symmetric and shortest
    /// coverage intervals, the trials, whether the adaptive run stabilized at
    /// `significant_digits` of u(y), whether the GUM interval is validated and the verdict
    /// under its rule; `check-turntable --jcgm101 --json`'s `jcgm101`. Seeded (`seed`:
    /// default the study's): the same answer for any thread count.
    #[pyo3(signature = (tolerances, significant_digits = 2, seed = None))]
    fn jcgm101(
        &self,
        py: Python<'_>,
        tolerances: PathBuf,
        significant_digits: u32,
        seed: Option<u64>,
    ) -> PyResult<Answer> {
        let s = &self.inner;
        if !(1..=tt_lab::budget_mc::MAX_DIGITS).contains(&significant_digits) {
            return Err(InputError::new_err(format!(
                "significant_digits: {significant_digits}: the significant digits of u(y) must be 1 to {}",
                tt_lab::budget_mc::MAX_DIGITS
            )));
        }
        let o = tt_lab::budget_mc::Options {
            significant_digits,
            seed,
            ..tt_lab::budget_mc::Options::default()
        };
        Answer::of(
            "jcgm101",
            py.detach(|| {
                let sheet = s
                    .load_sheet(&tolerances)
                    .map_err(tt_lab::InputError::from)?;
                let e2e = tt_lab::loaded::simulator(s)?;
                let ub = sheet.upper_bounds_rad();
                let Some(v) = tt_lab::vendor::spec::compute(s, &e2e, ub)? else {
                    return Err(tt_lab::InputError::new(
                        "specifications",
                        "the study gives no [[specifications]]: nothing for the Monte Carlo to draw",
                    )
                    .into());
                };
                let mc = tt_lab::budget_mc::compute(s, &e2e, ub, &v, &o)?;
                view(&tt_lab::budget_mc::Jcgm101Json::new(s, &mc))
            }),
        )
    }

    /// Which table errors the calibration estimates itself, and what is left to allocate,
    /// for a vendor's sheet (default: the direct allocation's box): `estimable --json`.
    #[pyo3(signature = (tolerances = None))]
    fn estimable(&self, py: Python<'_>, tolerances: Option<PathBuf>) -> PyResult<Answer> {
        let s = &self.inner;
        let o = tt_lab::estimable::Options { tolerances };
        Answer::of(
            "estimable",
            py.detach(|| {
                let a = tt_lab::estimable::estimable(s, &o)?;
                view(&tt_lab::estimable::to_json(s, &a))
            }),
        )
    }

    /// The Monte Carlo check of the two-step allocation's box (`samples`, `seed`: default
    /// the study's; same seed, same result for any thread count): `mc --json`.
    #[pyo3(signature = (samples = None, seed = None))]
    fn monte_carlo(
        &self,
        py: Python<'_>,
        samples: Option<u64>,
        seed: Option<u64>,
    ) -> PyResult<Answer> {
        let s = &self.inner;
        let mut o = tt_lab::monte_carlo::Options::default();
        o.samples = samples;
        o.seed = seed;
        Answer::of(
            "monte_carlo",
            py.detach(|| {
                let a = tt_lab::monte_carlo::monte_carlo(s, &o, &|_| {})?;
                view(&a.view(s, rayon::current_num_threads()))
            }),
        )
    }

    /// The test positions designed so the cheapest turntable meets every accuracy (the
    /// search over a grid of `step_deg`; with `time_budget_s` the positions and the dwell
    /// chosen together; with `rates_deg_per_s` the rate steps' rate chosen among them):
    /// `design-schedule --json`. `None`: the study's count and seed, the command line's
    /// defaults.
    #[pyo3(signature = (positions = None, step_deg = None, seed = None, time_budget_s = None, rates_deg_per_s = None))]
    fn design_schedule(
        &self,
        py: Python<'_>,
        positions: Option<usize>,
        step_deg: Option<f64>,
        seed: Option<u64>,
        time_budget_s: Option<f64>,
        rates_deg_per_s: Option<Vec<f64>>,
    ) -> PyResult<Answer> {
        let s = &self.inner;
        let mut o = tt_lab::design::schedule::Options::default();
        o.positions = positions;
        if let Some(step) = step_deg {
            o.step_deg = step;
        }
        o.seed = seed;
        o.time_budget_s = time_budget_s;
        o.rates_deg_per_s = rates_deg_per_s;
        let command = format!(
            "ttalloc.load_study(...).design_schedule(positions={positions:?}, step_deg={}, seed={seed:?}, time_budget_s={time_budget_s:?}, rates_deg_per_s={:?})",
            o.step_deg, o.rates_deg_per_s
        );
        Answer::of(
            "design_schedule",
            py.detach(|| {
                let a = tt_lab::design::schedule::design(s, &o, &|| {})?;
                view(&a.view(
                    s,
                    tt_lab::design::schedule::RunView {
                        command: &command,
                        written_study: None,
                        pareto_svg_note: None,
                    },
                ))
            }),
        )
    }

    /// The report of the study (`ttalloc report`), computed in memory: a dict of file name to
    /// its bytes (report.md, report.html, the SVG figures, the CSV tables, results.json). The
    /// package writes nothing: the caller decides where the files go. `tolerances`: a vendor's
    /// sheet checked in the report; `samples`, `seed`: the Monte Carlo's (default the study's).
    #[pyo3(signature = (tolerances = None, samples = None, seed = None))]
    fn report(
        &self,
        py: Python<'_>,
        tolerances: Option<PathBuf>,
        samples: Option<u64>,
        seed: Option<u64>,
    ) -> PyResult<std::collections::BTreeMap<String, Vec<u8>>> {
        let s = self.inner.clone();
        let files = py.detach(|| -> Result<Vec<tt_report::ReportFile>, tt_report::Error> {
            let mut o = tt_report::ReportOptions::default();
            o.samples = samples;
            o.seed = seed;
            if let Some(p) = &tolerances {
                o.tolerances = Some(s.load_sheet(p).map_err(tt_lab::InputError::from)?);
            }
            tt_report::Report::compute(s, o)?.files()
        });
        match files {
            Ok(f) => Ok(f.into_iter().map(|f| (f.name, f.bytes)).collect()),
            Err(tt_report::Error::Lab(e)) => Err(to_py(e)),
            Err(e) => Err(PyRuntimeError::new_err(e.to_string())),
        }
    }

    fn __repr__(&self) -> String {
        format!(
            "Study(name={:?}, path={:?})",
            self.inner.name, self.inner.path
        )
    }
}

/// Read and validate a study file.
#[pyfunction]
fn load_study(py: Python<'_>, path: PathBuf) -> PyResult<Study> {
    let inner = py
        .detach(|| tt_lab::loaded::load(Some(&path)))
        .map_err(|e| to_py(e.into()))?;
    Ok(Study { inner })
}

/// The answer to one question: its keys are the command line's `--json` keys.
#[pyclass(frozen, module = "ttalloc")]
pub struct Answer {
    question: &'static str,
    value: serde_json::Value,
}

impl Answer {
    fn of(question: &'static str, r: Result<serde_json::Value, LabError>) -> PyResult<Self> {
        r.map(|value| Self { question, value }).map_err(to_py)
    }
}

#[pymethods]
impl Answer {
    /// The question answered (`requirement`, `allocate`, `end_to_end`, `check_turntable`).
    #[getter]
    fn question(&self) -> &str {
        self.question
    }

    /// The answer as plain Python objects (the command line's JSON, `null` as `None`).
    fn to_dict<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        json_to_py(py, &self.value)
    }

    /// The top-level keys.
    fn keys(&self) -> Vec<String> {
        self.value
            .as_object()
            .map(|m| m.keys().cloned().collect())
            .unwrap_or_default()
    }

    fn __getitem__<'py>(&self, py: Python<'py>, key: &str) -> PyResult<Bound<'py, PyAny>> {
        match self.value.get(key) {
            Some(v) => json_to_py(py, v),
            None => Err(pyo3::exceptions::PyKeyError::new_err(key.to_string())),
        }
    }

    fn __contains__(&self, key: &str) -> bool {
        self.value.get(key).is_some()
    }

    fn __repr__(&self) -> String {
        format!("Answer({}, keys={:?})", self.question, self.keys())
    }
}

/// The overlapping Allan deviation of a log and its fitted noise (IEEE 952).
#[pyclass(frozen, module = "ttalloc")]
pub struct AllanResult {
    analysis: allan::Analysis,
}

fn column<'py>(
    py: Python<'py>,
    a: &allan::Analysis,
    f: impl Fn(&allan::AllanPoint) -> f64,
) -> Bound<'py, PyArray1<f64>> {
    PyArray1::from_vec(py, a.points().iter().map(f).collect())
}

#[pymethods]
impl AllanResult {
    /// Cluster times, s (a new array).
    #[getter]
    fn tau_s<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        column(py, &self.analysis, allan::AllanPoint::tau_s)
    }

    /// Overlapping Allan deviation at each cluster time, the samples' unit (a new array).
    #[getter]
    fn adev<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        column(py, &self.analysis, allan::AllanPoint::adev)
    }

    /// Lower end of each point's confidence band (a new array).
    #[getter]
    fn lower<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        column(py, &self.analysis, allan::AllanPoint::lower)
    }

    /// Upper end of each point's confidence band (a new array).
    #[getter]
    fn upper<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        column(py, &self.analysis, allan::AllanPoint::upper)
    }

    /// Samples analysed.
    #[getter]
    fn samples(&self) -> u64 {
        self.analysis.samples()
    }

    /// Sample rate, Hz.
    #[getter]
    fn rate_hz(&self) -> f64 {
        self.analysis.rate_hz()
    }

    /// White noise N (angle random walk), unit/sqrt(Hz): the -1/2 line at tau = 1 s.
    #[getter]
    fn white_noise_per_sqrt_hz(&self) -> f64 {
        self.analysis.fit().white_noise()
    }

    /// Bias instability B, the samples' unit.
    #[getter]
    fn bias_instability(&self) -> f64 {
        self.analysis.fit().bias_instability()
    }

    /// The `allan --json` keys (scalars) and `curve`, a dict of arrays (`tau_s`, `adev`,
    /// `lower`, `upper`, `edf`) where the command line prints a list of points.
    fn to_dict<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let a = &self.analysis;
        let f = a.fit();
        let d = PyDict::new(py);
        d.set_item("samples", a.samples())?;
        d.set_item("rate_hz", a.rate_hz())?;
        d.set_item("duration_s", a.samples() as f64 / a.rate_hz())?;
        d.set_item("confidence", a.confidence())?;
        d.set_item("overlap", a.overlap())?;
        d.set_item("white_noise_per_sqrt_hz", f.white_noise())?;
        d.set_item("white_noise_uncertainty", f.white_noise_uncertainty())?;
        d.set_item("bias_instability", f.bias_instability())?;
        d.set_item(
            "bias_instability_uncertainty",
            f.bias_instability_uncertainty(),
        )?;
        d.set_item("floor_tau_s", f.floor_tau_s())?;
        d.set_item("floor_adev", f.floor_adev_measured())?;
        d.set_item("floor_reached", f.floor_reached())?;
        d.set_item("rate_random_walk", f.rate_random_walk())?;
        d.set_item("quantization", f.quantization())?;
        d.set_item("rate_ramp", f.rate_ramp())?;
        let curve = PyDict::new(py);
        curve.set_item("tau_s", self.tau_s(py))?;
        curve.set_item("adev", self.adev(py))?;
        curve.set_item("lower", self.lower(py))?;
        curve.set_item("upper", self.upper(py))?;
        curve.set_item("edf", column(py, a, allan::AllanPoint::edf))?;
        d.set_item("curve", curve)?;
        Ok(d)
    }

    fn __repr__(&self) -> String {
        format!(
            "AllanResult(samples={}, rate_hz={}, points={})",
            self.analysis.samples(),
            self.analysis.rate_hz(),
            self.analysis.points().len()
        )
    }
}

/// The samples of `samples` read in place: a C-contiguous 1-D float64 NumPy array (nothing
/// else is accepted, so nothing is ever copied).
fn samples_in_place<'py>(
    samples: &Bound<'py, PyAny>,
) -> PyResult<numpy::PyReadonlyArray1<'py, f64>> {
    let refuse = |why: &str| {
        InputError::new_err(format!(
            "samples: {why}: pass a C-contiguous 1-D float64 NumPy array (np.ascontiguousarray(x, dtype=np.float64)); it is read in place, never copied"
        ))
    };
    let array = samples
        .cast::<PyArray1<f64>>()
        .map_err(|_| refuse("not a 1-D float64 NumPy array"))?;
    let ro = array
        .try_readonly()
        .map_err(|_| refuse("the array is mutably borrowed"))?;
    if ro.as_slice().is_err() {
        return Err(refuse("the array is not contiguous"));
    }
    Ok(ro)
}

/// The overlapping Allan deviation of `samples` (a C-contiguous 1-D float64 array, read in
/// place) at `rate_hz`, with the fitted noise terms; the GIL is released meanwhile.
#[pyfunction]
#[pyo3(name = "allan")]
fn allan_deviation(
    py: Python<'_>,
    samples: &Bound<'_, PyAny>,
    rate_hz: f64,
) -> PyResult<AllanResult> {
    let ro = samples_in_place(samples)?;
    let ys = ro
        .as_slice()
        .map_err(|e| PyRuntimeError::new_err(e.to_string()))?;
    let analysis = py
        .detach(|| allan::analyse(ys, allan::Settings::new(rate_hz)))
        .map_err(|e| allan_error(&e))?;
    Ok(AllanResult { analysis })
}

fn allan_error(e: &allan::AllanError) -> PyErr {
    use tt_core::ErrorClass;
    match e.input_field() {
        Some(field) => InputError::new_err(format!("{field}: {e}")),
        None => PyRuntimeError::new_err(e.to_string()),
    }
}

/// Seconds of the library call alone behind [`allan_deviation`] (`allan::analyse` on the same slice,
/// no conversion), for `python/bench/bench_allan.py`'s ratio in the same run.
#[pyfunction]
fn _library_seconds_allan(
    py: Python<'_>,
    samples: &Bound<'_, PyAny>,
    rate_hz: f64,
) -> PyResult<f64> {
    let ro = samples_in_place(samples)?;
    let ys = ro
        .as_slice()
        .map_err(|e| PyRuntimeError::new_err(e.to_string()))?;
    py.detach(|| {
        let t0 = std::time::Instant::now();
        let a = allan::analyse(ys, allan::Settings::new(rate_hz));
        let s = t0.elapsed().as_secs_f64();
        std::hint::black_box(a).map(|_| s)
    })
    .map_err(|e| allan_error(&e))
}

/// Seconds of the library calls alone behind [`Study::check_turntable`] (the same
/// computation without converting the answer to Python objects).
#[pyfunction]
#[pyo3(signature = (study, tolerances, samples = None, seed = None))]
fn _library_seconds_check_turntable(
    py: Python<'_>,
    study: &Study,
    tolerances: PathBuf,
    samples: Option<u64>,
    seed: Option<u64>,
) -> PyResult<f64> {
    let s = &study.inner;
    py.detach(|| {
        let t0 = std::time::Instant::now();
        let v = tt_lab::vendor::check(s, &tolerances, &vendor_options(samples, seed));
        let secs = t0.elapsed().as_secs_f64();
        std::hint::black_box(v).map(|_| secs)
    })
    .map_err(to_py)
}

/// A recording's columns as CSV text, streamed a row at a time (nothing kept but one line).
struct ColumnsCsv<'a> {
    header: Vec<u8>,
    columns: Vec<&'a [f64]>,
    row: usize,
    line: Vec<u8>,
    at: usize,
}

impl std::io::Read for ColumnsCsv<'_> {
    fn read(&mut self, out: &mut [u8]) -> std::io::Result<usize> {
        use std::io::Write;
        if self.at == self.line.len() {
            self.line.clear();
            self.at = 0;
            if !self.header.is_empty() {
                std::mem::swap(&mut self.line, &mut self.header);
            } else if self.columns.first().is_some_and(|c| self.row < c.len()) {
                for (j, c) in self.columns.iter().enumerate() {
                    let sep = if j == 0 { "" } else { "," };
                    write!(self.line, "{sep}{}", c[self.row])?;
                }
                self.line.push(b'\n');
                self.row += 1;
            }
        }
        let n = out.len().min(self.line.len() - self.at);
        out[..n].copy_from_slice(&self.line[self.at..self.at + n]);
        self.at += n;
        Ok(n)
    }
}

/// One CSV header field, quoted when it holds a comma, a quote or a line break (RFC 4180).
fn csv_field(name: &str) -> String {
    if name.contains([',', '"', '\n', '\r']) {
        format!("\"{}\"", name.replace('"', "\"\""))
    } else {
        name.to_string()
    }
}

/// The recording's columns: a dict of 1-D arrays (or sequences) or a pandas DataFrame, each
/// column as a contiguous float64 array (NumPy converts only what is not one already).
fn recording_columns<'py>(
    recording: &Bound<'py, PyAny>,
) -> PyResult<Vec<(String, numpy::PyReadonlyArray1<'py, f64>)>> {
    let py = recording.py();
    let np = py.import("numpy")?;
    let names: Vec<Bound<'py, PyAny>> = if let Ok(d) = recording.cast::<PyDict>() {
        d.keys().iter().collect()
    } else if recording.hasattr("columns")? {
        recording
            .getattr("columns")?
            .try_iter()?
            .collect::<PyResult<_>>()?
    } else {
        return Err(InputError::new_err(
            "recording: give a dict of column name to 1-D array, or a pandas DataFrame",
        ));
    };
    let mut out = Vec::with_capacity(names.len());
    for k in names {
        let name: String = k
            .extract()
            .map_err(|_| InputError::new_err("recording: a column name is not a str"))?;
        let bad = |why: String| InputError::new_err(format!("recording: column `{name}`: {why}"));
        let array = np
            .call_method1("ascontiguousarray", (recording.get_item(&k)?, "float64"))
            .map_err(|e| bad(format!("not an array of numbers ({e})")))?;
        let array = array
            .cast_into::<PyArray1<f64>>()
            .map_err(|_| bad("not one-dimensional".into()))?;
        let ro = array
            .try_readonly()
            .map_err(|_| bad("the array is mutably borrowed".into()))?;
        out.push((name, ro));
    }
    Ok(out)
}

/// Calibrate a recording of the calibration `study` planned (`calib-run`: segments detected,
/// the coefficients fitted, the study's specifications and the caller's `specs` (coefficient
/// name to limit, in the coefficient's unit) judged under ILAC-G8): `calibrate --json`.
///
/// `recording`: a dict of column name to 1-D array, or a pandas DataFrame, with a time
/// column (`t_s`, `time_s`, `sample` or `index`) and one column per output named as the
/// study names it. It is streamed to the library a row at a time; the GIL is released.
#[pyfunction]
#[pyo3(signature = (study, recording, specs = None, robust = false))]
fn calibrate(
    py: Python<'_>,
    study: &Study,
    recording: &Bound<'_, PyAny>,
    specs: Option<std::collections::BTreeMap<String, f64>>,
    robust: bool,
) -> PyResult<Answer> {
    let columns = recording_columns(recording)?;
    let slices = columns
        .iter()
        .map(|(n, a)| {
            a.as_slice().map_err(|_| {
                InputError::new_err(format!("recording: column `{n}` is not contiguous"))
            })
        })
        .collect::<PyResult<Vec<_>>>()?;
    if let Some(((n0, _), first)) = columns.first().zip(slices.first()) {
        for ((n, _), c) in columns.iter().zip(&slices) {
            if c.len() != first.len() {
                return Err(InputError::new_err(format!(
                    "recording: column `{n}` has {} values, `{n0}` {}",
                    c.len(),
                    first.len()
                )));
            }
        }
    }
    let header = columns
        .iter()
        .map(|(n, _)| csv_field(n))
        .collect::<Vec<_>>()
        .join(",")
        + "\n";
    let reader = ColumnsCsv {
        header: header.into_bytes(),
        columns: slices,
        row: 0,
        line: Vec::new(),
        at: 0,
    };
    let mut o = tt_lab::calibrate::Options::default();
    o.robust = robust;
    o.specs = specs
        .unwrap_or_default()
        .into_iter()
        .map(|(coefficient, limit)| calib_run::Spec {
            coefficient,
            limit,
            unit: None,
        })
        .collect();
    let s = &study.inner;
    Answer::of(
        "calibrate",
        py.detach(|| {
            let a = tt_lab::calibrate::calibrate(s, reader, "recording", &o)?;
            view(&a.view(None))
        }),
    )
}

/// A simulated recording of the calibration `study` plans, as CSV text (the tests' and the
/// docs' recording: `calib_run::simulate` with the study's sensor as the truth).
#[pyfunction]
fn _simulate_recording(
    py: Python<'_>,
    study: &Study,
    sample_rate_hz: f64,
    dwell_s: f64,
    seed: u64,
) -> PyResult<String> {
    let s = &study.inner;
    py.detach(|| {
        let settings =
            calib_run::simulate::SimSettings::for_study(s, sample_rate_hz, dwell_s, seed);
        let mut buf = Vec::new();
        calib_run::simulate::simulate_recording(s, &s.sensor, &settings, &mut buf)
            .map_err(|e| to_py(tt_lab::calibrate::run_error(e)))?;
        String::from_utf8(buf).map_err(|e| PyRuntimeError::new_err(e.to_string()))
    })
}

/// The native module (`ttalloc._native`); `ttalloc/__init__.py` re-exports it.
#[pymodule]
fn _native(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add("InputError", m.py().get_type::<InputError>())?;
    m.add_class::<Study>()?;
    m.add_class::<Answer>()?;
    m.add_class::<AllanResult>()?;
    m.add_function(wrap_pyfunction!(load_study, m)?)?;
    m.add_function(wrap_pyfunction!(calibrate, m)?)?;
    m.add_function(wrap_pyfunction!(_simulate_recording, m)?)?;
    m.add_function(wrap_pyfunction!(allan_deviation, m)?)?;
    m.add_function(wrap_pyfunction!(_library_seconds_allan, m)?)?;
    m.add_function(wrap_pyfunction!(_library_seconds_check_turntable, m)?)?;
    Ok(())
}
