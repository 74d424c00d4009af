//! The physical ranges every number of a study (and of a tolerance file or a turntable CSV)
//! must lie in. A value outside is rejected at the input with the file, the key and the range,
//! so that no absurd value reaches a computation and comes out as confident nonsense.
//!
//! | quantity | range | why |
//! |---|---|---|
//! | latitude | $[-90, 90]$ deg | a latitude |
//! | earth rate | $[10^{-6}, 10^{-3}]$ rad/s | planets' rotation rates (Earth $7.29\times10^{-5}$) with a wide margin |
//! | output accuracy | $[10^{-12}, 10^{6}]$ output units | positive and finite; beyond, the analysis is meaningless in any unit |
//! | coefficient value | $|v| \le 10^{6}$ output unit per regressor unit | Table 1's largest is 105 deg/h; a million keeps every product finite |
//! | joint angle, fixed angle, range end | $[-720, 720]$ deg | two turns either way |
//! | joint range width | $(0, 360]$ deg | at most a turn |
//! | given requirement | $[10^{-9}, 10]$ deg | the first-order theory of §2-4 holds for small angles only; $10^{-9}$ deg (3.6 micro-arcseconds) is a thousand times below the best angle metrology, and the exact chain's rounding ($\sim10^{-16}$ rad) stays $10^{-7}$ of it (the objective $J \propto I^{-2}$ overflows below $\sim10^{-140}$ deg) |
//! | lower bound, tolerance (angle) | $[0, 600]$ arcmin | 10 deg, far beyond any turntable |
//! | tolerance (translation) | $[0, 1000]$ mm | a metre |
//! | Monte Carlo samples | $[1, 10^{10}]$ | one limit for every command that takes a count (`monte_carlo.samples`, `--samples`): the end-to-end draws about $10^6$ turntables per second on two cores, so $10^{10}$ take about three hours |
//! | noise: white density, bias instability, quantization, rate random walk, rate ramp | $[0, 10^{6}]$ in the key's unit (output unit, or the datasheet unit the key names) | non-negative; like the accuracy, beyond $10^6$ nothing is meaningful |
//! | bias correlation time | $(0, 10^{7}]$ s | about 4 months: longer is a constant bias |
//! | dwell per position | $(0, 86\,400]$ s, and at least one sample ($f_s T \ge 1$) | a day per position |
//! | move time | $[0, 86\,400]$ s | a day |
//! | sample rate | $(0, 10^{6}]$ Hz | inertial sensors sample at up to a few kHz |
//! | study `name` | 1 to 64 of `A-Z a-z 0-9 . _ -`, first a letter or digit | it names the report directory (`target/report/<name>`): one safe path component on every system |
//! | test positions | $[1, 10\,000]$ | a lab's schedule has tens to hundreds; every command's memory grows linearly with the count (measured at 10,000 on two shared cores: `requirement` 23 s 63 MB, `allocate` 24 s 56 MB, `mc` 37 s 55 MB, `estimable` 35 s 106 MB); the Monte Carlo commands (`end-to-end`, `check-turntable`, `report`) take time in samples times positions (`end-to-end --samples 1500`: 8 s and 32 MB at 1,000 positions, 25 s and 64 MB at 3,000, about 5 µs per sample and position); the angle-dependent model at most `e2e_verify::angle::MAX_EXPANDED_VALUES` values (positions times distinct shaft angles, refused beyond naming `calibration.positions_deg`) |

/// Latitude range, deg.
pub(crate) const LATITUDE_DEG: (f64, f64) = (-90.0, 90.0);
/// Earth-rate range, rad/s.
pub(crate) const EARTH_RATE_RAD_PER_S: (f64, f64) = (1e-6, 1e-3);
/// Output accuracy range, output units.
pub(crate) const ACCURACY: (f64, f64) = (1e-12, 1e6);
/// Largest coefficient magnitude, output unit per regressor unit.
pub(crate) const COEFFICIENT_ABS_MAX: f64 = 1e6;
/// Largest joint, fixed or range angle magnitude, deg.
pub(crate) const ANGLE_ABS_MAX_DEG: f64 = 720.0;
/// Given requirement range, deg.
pub const REQUIREMENT_DEG: (f64, f64) = (1e-9, 10.0);
/// Lower bound / angular tolerance range, arcmin.
pub(crate) const ANGLE_TOLERANCE_ARCMIN: (f64, f64) = (0.0, 600.0);
/// Translation tolerance range, mm.
pub(crate) const TRANSLATION_TOLERANCE_MM: (f64, f64) = (0.0, 1000.0);
/// Rate limit of a joint (`turntable.max_rate_deg_per_s.<joint>`), deg/s: rate tables reach
/// a few thousand deg/s, centrifuges more.
pub(crate) const MAX_RATE_DEG_PER_S: (f64, f64) = (0.0, 1e5);
/// Smallest magnitude of a rate step's rate (`calibration.rate_steps[i].rate_deg_per_s`),
/// deg/s: one revolution in about 11 years; below it a rate is zero to the computation
/// (5e-324 deg/s is 0 rad/s).
pub(crate) const MIN_RATE_STEP_DEG_PER_S: f64 = 1e-6;
/// Revolutions of a rate step.
pub(crate) const MAX_REVOLUTIONS: u64 = 1_000_000;
/// Largest lever-arm component (`sensor.lever_arm_m`), m.
pub(crate) const LEVER_ARM_ABS_MAX_M: f64 = 10.0;
/// Rate tolerances (rate accuracy, ripple), ppm.
pub(crate) const RATE_TOLERANCE_PPM: (f64, f64) = (0.0, 1e5);
/// Largest Monte Carlo sample count, of a study (`monte_carlo.samples`) and of `--samples`
/// alike: the end-to-end verification's limit (`e2e_verify::MAX_SAMPLES`), so that every
/// command refuses a larger count before any work, naming the key the user wrote.
pub const MAX_SAMPLES: u64 = 10_000_000_000;
/// Largest number of test positions in a schedule (`calibration.positions_deg`, and
/// `design-schedule --positions`).
pub const MAX_POSITIONS: usize = 10_000;
/// Largest study or tolerance file read, bytes (a study is a few kilobytes).
pub(crate) const MAX_FILE_BYTES: u64 = 4 << 20;
/// Largest white-noise density, bias instability, quantization step, rate random walk or rate
/// ramp, in the key's unit.
pub const NOISE_MAX: f64 = 1e6;
/// Bias correlation time range (exclusive lower end), s.
pub const CORRELATION_S: (f64, f64) = (0.0, 1e7);
/// Dwell time range per position (exclusive lower end), s.
pub const DWELL_S: (f64, f64) = (0.0, 86_400.0);
/// Move time range between positions, s.
pub(crate) const MOVE_S: (f64, f64) = (0.0, 86_400.0);
/// Sample rate range (exclusive lower end), Hz.
pub(crate) const SAMPLE_RATE_HZ: (f64, f64) = (0.0, 1e6);
/// Longest study `name`, characters (it is a file name: see [`crate::is_name_slug`]).
pub(crate) const MAX_NAME_CHARS: usize = 64;
