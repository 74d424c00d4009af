//! The fast exact evaluation of eq 23-24 for any turntable: its evaluation plan run on lanes
//! of samples with quaternions of the small error rotations.
//!
//! # Formula
//! [`tt_kinematics::Turntable::plan`] writes $\Delta\mathbf R = \mathbf R_d^T\mathbf R_t$ as a
//! flat program on a quaternion $q$ (the joints before the first error cancel and are left
//! out): $q \leftarrow q \otimes (\cos\tfrac x2, \sin\tfrac x2\,\hat e_a)$ for an error rotation
//! $R_a(x)$ (8 products: the quaternion analogue of "an elementary rotation touches two
//! columns", at half the cost of a 3x3 update), and $q \leftarrow n^{-1} \otimes q \otimes n$
//! for a joint or fixed rotation $n$ about axis $a$ (the scalar part and the $a$ part are kept,
//! the other two are turned). With $q = (w, x, y, z)$ the eq-24 read-out is
//! $$\Delta\psi = \Delta R_{13} = 2(xz + wy),\quad \Delta\theta = \Delta R_{21} = 2(xy + wz),\quad
//!   \Delta\gamma = \Delta R_{32} = 2(yz + wx).$$
//! For the paper's table this is about 70 multiplications against about 300 for the ten dense
//! 3x3 products of the plain chain.
//!
//! # Evaluation
//! The plan is compiled once per run (`CompiledPlan`) into a list of operations that carry
//! their axis, so evaluating one needs no lookup in the description: the first two error
//! rotations fused into one start,
//! $(c_a, s_a\hat e_A)(c_b, s_b\hat e_B) = (c_ac_b,\ s_ac_b\hat e_A + c_as_b\hat e_B +
//! s_as_b\,\hat e_A \times \hat e_B)$ (the products the single steps compute from $q = 1$,
//! without those by zero); consecutive error rotations paired into one operation (one
//! dispatch for two); joints and fixed rotations as conjugation slots (a fixed rotation's slot
//! holds constant columns, so that every conjugation is the same code). A block of
//! [`BLOCK_CAPACITY`] samples is then evaluated in three passes:
//! 1. per angular error, one column loop turns its words into $(\sin\tfrac x2, \cos\tfrac x2)$
//!    (or $\tan\tfrac x2$, below), the sign of a negative axis folded in;
//! 2. per free joint, $(\sin\phi, \cos\phi)$: a scalar loop fetches the table entries (a
//!    lookup does not vectorise), then a vectorised loop computes the remainder's series and
//!    the angle-sum formula (per sample exactly the arithmetic of [`sin_cos_turn`]);
//! 3. the samples are taken [`LANES`] at a time, the four quaternion components held in
//!    fixed-size arrays of [`LANES`] values (registers: one AVX2 vector holds four), and the
//!    operations are applied in order, one `match` per operation per lane group, then the
//!    read-out.
//!
//! Joints that cancel are drawn but their sine and cosine are never computed. Every
//! per-sample operation is an IEEE operation in a fixed order (no FMA, no reassociation), so
//! the vector width does not change a bit of the result.
//!
//! $\sin\tfrac x2, \cos\tfrac x2$ of the error angles use the tier chosen once per run from the
//! box ([`Tier`]): Taylor series exact to rounding ($|x| \le$ [`SHORT_SERIES_MAX_ABS_RAD`]:
//! $\tfrac x2 - \tfrac{x^3}{48}$, $1 - \tfrac{x^2}{8}$, truncation below $10^{-17}$; $|x| \le$
//! [`SERIES_MAX_ABS_RAD`]: $+\tfrac{x^5}{3840}$, $+\tfrac{x^4}{384}$, truncation below
//! $6\cdot10^{-18}$), `f64::sin_cos` beyond. When every lower bound is zero and every bound
//! within [`SHORT_SERIES_MAX_ABS_RAD`] (the paper's case: Table 4 and our allocation), the
//! chain uses *unnormalised* quaternions $(1, \tau\,\hat e_a) = (\cos\tfrac x2)^{-1}(\cos\tfrac x2,
//! \sin\tfrac x2\,\hat e_a)$, $\tau = \tan\tfrac x2$: a right product by one costs 4 products
//! instead of 8 and no cosine is needed; conjugations keep the norm, and the read-out divides
//! by $|\tilde q|^2$ once: $\Delta R_{13} = 2(\tilde x\tilde z + \tilde w\tilde y)/|\tilde q|^2$,
//! and so on. $\tau$ comes straight from the half-integer $t$ of the word ($\chi_i = t\,s_i$,
//! $s_i = \mathrm{UB}_i 2^{-31}$): $\tan\tfrac{\chi}{2} \approx t(\tfrac{s}{2} + t^2
//! \tfrac{s^3}{24})$, truncation $|\chi|^5/240 \le 4\cdot10^{-21}$ rad.
//!
//! Sine and cosine of a full-turn joint angle $2\pi w 2^{-32}$ come from the integer word
//! ([`sin_cos_turn`]: a 256-entry table and a degree-7 series of the exact remainder); of an
//! angle of a joint with a range, from the same table after a floating-point reduction
//! (`sin_cos_reduced`); of an angle beyond $\pm 4\pi$, from `f64::sin_cos`.
//!
//! For the paper's table every sample gets exactly the operations of the crate's earlier
//! hand-written kernel, in the same order, so the results are bit-identical to it (tested
//! against a kept copy, `baseline`, in every tier and with zero bounds, and against
//! values pinned from it). The result equals the plain
//! chain ([`tt_kinematics::ExactChain`] with the eq-24 read-out) to rounding; the tests check
//! $10^{-15}$ rad per sample on the paper's and a three-axis table, in every tier.
//!
//! # Reference
//! Paper eq 17-25; Table 3 (rotation order).

use crate::bounds::ErrorBox;
use crate::sampler::{BLOCK_CAPACITY, JointLaw, RAD_PER_TURN_WORD, SampleBlock, TurntableSampler};
use std::f64::consts::TAU;
use tt_kinematics::{
    Axis, KinematicsError, OrientationError, OrientationErrorModel, PlanStep, Pose, Turntable,
    TurntableErrors, quat_conjugate_axis, quat_mul_axis, quat_readout,
};

/// Largest $|\chi_i|$ (rad, about 27.5 arcmin) for which the medium Taylor series
/// $\sin\tfrac x2 \approx \tfrac x2 - \tfrac{x^3}{48} + \tfrac{x^5}{3840}$,
/// $\cos\tfrac x2 \approx 1 - \tfrac{x^2}{8} + \tfrac{x^4}{384}$ are used; their truncation
/// errors ($|x|^7/645120$, $|x|^6/46080$) are then below $6\cdot10^{-18}$, far under one unit
/// in the last place of 1 ($2.2\cdot10^{-16}$). Larger angles use `f64::sin_cos`.
pub const SERIES_MAX_ABS_RAD: f64 = 8e-3;

/// Largest $|\chi_i|$ (rad, about 0.86 arcmin) for which the short series
/// $\sin\tfrac x2 \approx \tfrac x2 - \tfrac{x^3}{48}$, $\cos\tfrac x2 \approx 1 - \tfrac{x^2}{8}$
/// are used by a Monte Carlo run whose whole box lies inside it (Table 4 does: its largest
/// bound is 0.78 arcmin); truncation errors $|x|^5/3840$ and $|x|^4/384 \le 10^{-17}$.
pub const SHORT_SERIES_MAX_ABS_RAD: f64 = 2.5e-4;

/// Joint angles (rad) beyond which a ranged joint's sine and cosine come from `f64::sin_cos`
/// instead of the table reduction (whose table wraps with $2\pi$ rounded: $2.4\cdot10^{-16}$
/// rad per turn).
const REDUCTION_MAX_ABS_RAD: f64 = 2.0 * TAU;

/// Samples evaluated together by the plan interpreter (one AVX2 vector of `f64`; measured
/// against 2 and 8, see the README).
pub const LANES: usize = 8;

/// Lane groups per block.
pub(crate) const GROUPS: usize = BLOCK_CAPACITY / LANES;

/// A column of a block, lane-grouped: `col[g][l]` is sample `g * LANES + l`.
pub(crate) type Col = [[f64; LANES]; GROUPS];

/// How a run evaluates $(\sin\tfrac x2, \cos\tfrac x2)$ of its error angles: chosen once per
/// run from the box ([`Tier::for_box`]), so the kernel has no per-sample branch.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Tier {
    /// Every lower bound zero, every bound within [`SHORT_SERIES_MAX_ABS_RAD`]: unnormalised
    /// quaternions from $\tan\tfrac x2$ of the word's half-integer (the paper's case).
    Tangent,
    /// Every bound within [`SHORT_SERIES_MAX_ABS_RAD`] (some lower bound positive): the short
    /// series.
    Short,
    /// Every bound within [`SERIES_MAX_ABS_RAD`]: the medium series.
    Medium,
    /// Any box: the medium series for small angles, `f64::sin_cos` beyond.
    Any,
}

impl Tier {
    /// The tier of a box.
    #[must_use]
    pub fn for_box(bounds: &ErrorBox) -> Self {
        let max = bounds.max_ub_rad();
        if max <= SHORT_SERIES_MAX_ABS_RAD {
            if bounds.lower_bounds_are_zero() {
                Tier::Tangent
            } else {
                Tier::Short
            }
        } else if max <= SERIES_MAX_ABS_RAD {
            Tier::Medium
        } else {
            Tier::Any
        }
    }

    /// Short name (`tangent`, `short`, `medium`, `any`).
    #[must_use]
    pub fn name(self) -> &'static str {
        match self {
            Tier::Tangent => "tangent",
            Tier::Short => "short",
            Tier::Medium => "medium",
            Tier::Any => "any",
        }
    }
}

/// Tier codes of the const-generic kernels.
pub(crate) const TIER_TANGENT: u8 = 0;
pub(crate) const TIER_SHORT: u8 = 1;
pub(crate) const TIER_MEDIUM: u8 = 2;
pub(crate) const TIER_ANY: u8 = 3;

/// $(\sin\tfrac x2, \cos\tfrac x2)$ by the short series; valid for $|x| \le$
/// [`SHORT_SERIES_MAX_ABS_RAD`].
#[inline(always)]
pub(crate) fn half_sin_cos_short(x: f64) -> (f64, f64) {
    let x2 = x * x;
    (x * (0.5 - x2 * (1.0 / 48.0)), 1.0 - x2 * 0.125)
}

/// $(\sin\tfrac x2, \cos\tfrac x2)$ by the medium series; valid for $|x| \le$ [`SERIES_MAX_ABS_RAD`].
#[inline(always)]
pub(crate) fn half_sin_cos_series(x: f64) -> (f64, f64) {
    let x2 = x * x;
    let s = x * (0.5 + x2 * (-1.0 / 48.0 + x2 * (1.0 / 3840.0)));
    let c = 1.0 + x2 * (-0.125 + x2 * (1.0 / 384.0));
    (s, c)
}

/// $(\sin\tfrac x2, \cos\tfrac x2)$ for any finite $x$.
#[inline(always)]
pub(crate) fn half_sin_cos(x: f64) -> (f64, f64) {
    if x.abs() <= SERIES_MAX_ABS_RAD {
        half_sin_cos_series(x)
    } else {
        (0.5 * x).sin_cos()
    }
}

/// $(\sin\tfrac x2, \cos\tfrac x2)$ of tier `TIER` (every $x$ inside its range).
#[inline(always)]
fn half_sin_cos_tier<const TIER: u8>(x: f64) -> (f64, f64) {
    match TIER {
        TIER_TANGENT | TIER_SHORT => half_sin_cos_short(x),
        TIER_MEDIUM => half_sin_cos_series(x),
        _ => half_sin_cos(x),
    }
}

/// Entries of the pose table: $(\sin, \cos)$ of $2\pi j / 256$.
const TURN_TABLE_LEN: usize = 256;

/// The pose table type.
pub(crate) type TurnTable = [(f64, f64); TURN_TABLE_LEN];

/// $(\sin, \cos)$ of $2\pi j / 256$, $j = 0 \dots 255$, from `f64::sin_cos`.
pub(crate) fn turn_table() -> &'static TurnTable {
    static TABLE: std::sync::OnceLock<TurnTable> = std::sync::OnceLock::new();
    TABLE.get_or_init(|| {
        std::array::from_fn(|j| {
            (std::f64::consts::TAU * j as f64 / TURN_TABLE_LEN as f64).sin_cos()
        })
    })
}

/// The table entry $j$ (`j` taken modulo 256).
#[inline(always)]
fn table_entry(table: &TurnTable, j: usize) -> (f64, f64) {
    table[j & (TURN_TABLE_LEN - 1)]
}

/// $(\sin(\alpha_j + d), \cos(\alpha_j + d))$ from the table entry $(\sin\alpha_j, \cos\alpha_j)$
/// and $\sin d, \cos d$ by Taylor polynomials of degree 7 and 6 (truncation below $10^{-19}$
/// for $|d| \le \pi/256$), by the angle-sum formula.
#[inline(always)]
fn rotate_entry((sj, cj): (f64, f64), d: f64) -> (f64, f64) {
    let d2 = d * d;
    let sd = d * (1.0 + d2 * (-1.0 / 6.0 + d2 * (1.0 / 120.0 - d2 * (1.0 / 5040.0))));
    let cd = 1.0 + d2 * (-0.5 + d2 * (1.0 / 24.0 - d2 * (1.0 / 720.0)));
    (sj * cd + cj * sd, cj * cd - sj * sd)
}

/// Nearest table angle of a full-turn word: $j = \lfloor (w + 2^{23}) / 2^{24} \rfloor$
/// ($0 \dots 256$, exact).
#[inline(always)]
fn turn_index(w: u32) -> usize {
    (w.wrapping_add(1 << 23) >> 24) as usize
}

/// The remainder $d = 2\pi (w - 2^{24} j) 2^{-32}$, $|d| \le \pi/256$ (one rounding).
#[inline(always)]
fn turn_remainder(w: u32) -> f64 {
    let j = turn_index(w);
    let r = w.wrapping_sub((j as u32) << 24) as i32;
    f64::from(r) * RAD_PER_TURN_WORD
}

/// [`sin_cos_turn`] with the table passed in.
#[inline(always)]
pub(crate) fn sin_cos_turn_with(table: &TurnTable, w: u32) -> (f64, f64) {
    // nearest table angle 2 pi j / 256 (top 8 bits, rounded), remainder |d| <= pi / 256
    rotate_entry(table_entry(table, turn_index(w)), turn_remainder(w))
}

/// $1.5 \cdot 2^{52}$: adding it rounds a value below $2^{51}$ in magnitude to an integer,
/// which then sits in the low mantissa bits.
const ROUND_MAGIC: f64 = 6_755_399_441_055_744.0;

/// Nearest table angle of an angle $a$: $256\,a/2\pi$ rounded to the nearest integer $j$,
/// returned as (`j` modulo $2^{51}$ from the mantissa bits, `j` as a float).
#[inline(always)]
fn reduced_index(a: f64) -> (usize, f64) {
    let shifted = a * (TURN_TABLE_LEN as f64 / TAU) + ROUND_MAGIC;
    (
        (shifted.to_bits() & (TURN_TABLE_LEN as u64 - 1)) as usize,
        shifted - ROUND_MAGIC,
    )
}

/// $(\sin a, \cos a)$ of the angle of a joint with a range (the fast path's method for
/// $|a| \le 4\pi$): the nearest table angle $j\,2\pi/256$ by rounding $256\,a/2\pi$, the
/// remainder $d = a - j\,(2\pi/256)$ (one rounding, $|d| \lesssim \pi/256$), then as
/// [`sin_cos_turn`]. Agrees with `f64::sin_cos` to about $10^{-15}$ for $|a| \le 4\pi$ (tested;
/// the table wraps with $2\pi$ rounded, $2.4\cdot10^{-16}$ rad per turn).
#[must_use]
pub fn sin_cos_reduced(a_rad: f64) -> (f64, f64) {
    let (j, jf) = reduced_index(a_rad);
    rotate_entry(
        table_entry(turn_table(), j),
        a_rad - jf * (TAU / TURN_TABLE_LEN as f64),
    )
}

/// $(\sin\phi, \cos\phi)$ of the full-turn angle $\phi = 2\pi\,w\,2^{-32}$, from the integer `w`.
///
/// The nearest of 256 table angles $2\pi j/256$ is taken from the top bits of `w`, exactly;
/// the remainder $|\delta| \le \pi/256$ is formed with one rounding; $\sin\delta, \cos\delta$
/// are Taylor polynomials of degree 7 and 6 (truncation below $10^{-19}$); the angle-sum
/// formula combines them with the table's `f64::sin_cos` values. Agrees with
/// `f64::sin_cos(phi)` to a few $10^{-16}$ (tested) at a fraction of its cost.
#[must_use]
pub fn sin_cos_turn(w: u32) -> (f64, f64) {
    sin_cos_turn_with(turn_table(), w)
}

/// One operation of a compiled plan (see the [module](self)); the axis is part of the
/// operation so that evaluating it needs no other lookup.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) enum Op {
    /// $q \leftarrow (c, s\,\hat e_x)$ for error column `.0` (the first operation: $q = 1$
    /// before it).
    InitX(usize),
    /// $q \leftarrow (c, s\,\hat e_y)$.
    InitY(usize),
    /// $q \leftarrow (c, s\,\hat e_z)$.
    InitZ(usize),
    /// $q \leftarrow (c_a, s_a\hat e_A) \otimes (c_b, s_b\hat e_B)$ for error columns `.1`
    /// (axis $A$) and `.2` (axis $B \ne A$), the first two operations fused:
    /// $(c_ac_b,\ s_ac_b\hat e_A + c_as_b\hat e_B + s_as_b\,\hat e_A\times\hat e_B)$
    /// (the very products the generic steps compute from $q = 1$, without the products by
    /// zero).
    Init2(Pair, usize, usize),
    /// $q \leftarrow q \otimes (c, s\,\hat e_x)$ for error column `.0`.
    ErrX(usize),
    /// The same about $y$.
    ErrY(usize),
    /// The same about $z$.
    ErrZ(usize),
    /// Two consecutive error rotations (about $x$ then $x$) in one operation: columns `.0`
    /// then `.1` (fewer dispatches; the same arithmetic as two single operations).
    ErrXX(usize, usize),
    /// About $x$ then $y$.
    ErrXY(usize, usize),
    /// About $x$ then $z$.
    ErrXZ(usize, usize),
    /// About $y$ then $x$.
    ErrYX(usize, usize),
    /// About $y$ then $y$.
    ErrYY(usize, usize),
    /// About $y$ then $z$.
    ErrYZ(usize, usize),
    /// About $z$ then $x$.
    ErrZX(usize, usize),
    /// About $z$ then $y$.
    ErrZY(usize, usize),
    /// About $z$ then $z$.
    ErrZZ(usize, usize),
    /// Conjugation by rotation slot `.0` about $x$ (a free joint, or a fixed rotation: slots
    /// after the joints hold constant columns, so that every conjugation is the same code;
    /// scalar constants in the loop would lead the compiler to pack quaternion components,
    /// not samples, into vectors).
    JointX(usize),
    /// The same about $y$.
    JointY(usize),
    /// The same about $z$.
    JointZ(usize),
}

/// The axes $(A, B)$ of a fused first pair of error rotations.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Pair {
    Xy,
    Xz,
    Yx,
    Yz,
    Zx,
    Zy,
}

impl Pair {
    fn of(a: Axis, b: Axis) -> Option<Self> {
        Some(match (a, b) {
            (Axis::X, Axis::Y) => Pair::Xy,
            (Axis::X, Axis::Z) => Pair::Xz,
            (Axis::Y, Axis::X) => Pair::Yx,
            (Axis::Y, Axis::Z) => Pair::Yz,
            (Axis::Z, Axis::X) => Pair::Zx,
            (Axis::Z, Axis::Y) => Pair::Zy,
            _ => return None,
        })
    }
}

/// A joint whose angle the orientation error depends on.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct FreeJoint {
    /// Its index in the pose.
    pub joint: usize,
    /// $\pm 1$ (negative axis).
    pub sign: f64,
}

/// A turntable's evaluation plan compiled for the lane interpreter (see the [module](self)).
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct CompiledPlan {
    pub ops: Vec<Op>,
    /// Sign ($\pm1$) of the axis of every angular error, order of $\chi$.
    pub chi_sign: Vec<f64>,
    /// The free joints in plan order (rotation slot `k < free.len()` is `free[k]`).
    pub free: Vec<FreeJoint>,
    /// $(\sin, \cos)$ of the fixed rotations in plan order (rotation slot `free.len() + k`).
    pub fixed: Vec<(f64, f64)>,
    /// Number of joints of the turntable.
    pub n_joints: usize,
}

impl CompiledPlan {
    /// Compile [`Turntable::plan`].
    pub(crate) fn new(turntable: &Turntable) -> Self {
        let mut ops = Vec::with_capacity(turntable.plan().len());
        let mut chi_sign = vec![1.0; turntable.n_rotation_errors()];
        let mut free = Vec::new();
        let mut fixed = Vec::new();
        let n_free = turntable.free_joints().len();
        for step in turntable.plan() {
            ops.push(match *step {
                PlanStep::Error { chi, axis, sign } => {
                    chi_sign[chi] = sign;
                    match (ops.is_empty(), axis) {
                        (true, Axis::X) => Op::InitX(chi),
                        (true, Axis::Y) => Op::InitY(chi),
                        (true, Axis::Z) => Op::InitZ(chi),
                        (false, Axis::X) => Op::ErrX(chi),
                        (false, Axis::Y) => Op::ErrY(chi),
                        (false, Axis::Z) => Op::ErrZ(chi),
                    }
                }
                PlanStep::Joint { joint, axis, sign } => {
                    let slot = free.len();
                    free.push(FreeJoint { joint, sign });
                    match axis {
                        Axis::X => Op::JointX(slot),
                        Axis::Y => Op::JointY(slot),
                        Axis::Z => Op::JointZ(slot),
                    }
                }
                PlanStep::Fixed { axis, sin, cos } => {
                    let slot = n_free + fixed.len();
                    fixed.push((sin, cos));
                    match axis {
                        Axis::X => Op::JointX(slot),
                        Axis::Y => Op::JointY(slot),
                        Axis::Z => Op::JointZ(slot),
                    }
                }
            });
        }
        debug_assert_eq!(
            free.len(),
            n_free,
            "every free joint appears once in the plan"
        );
        // fuse the first two error rotations when their axes differ
        let axis_of = |op: &Op| match *op {
            Op::InitX(i) | Op::ErrX(i) => Some((Axis::X, i)),
            Op::InitY(i) | Op::ErrY(i) => Some((Axis::Y, i)),
            Op::InitZ(i) | Op::ErrZ(i) => Some((Axis::Z, i)),
            _ => None,
        };
        if let [first, second, ..] = ops.as_slice() {
            if let (Some((a, i)), Some((b, j))) = (axis_of(first), axis_of(second)) {
                if let Some(pair) = Pair::of(a, b) {
                    ops.splice(0..2, [Op::Init2(pair, i, j)]);
                }
            }
        }
        // then pair up consecutive single error rotations
        let mut fused = Vec::with_capacity(ops.len());
        let mut k = 0;
        while k < ops.len() {
            let single = |op: &Op| match *op {
                Op::ErrX(i) => Some((Axis::X, i)),
                Op::ErrY(i) => Some((Axis::Y, i)),
                Op::ErrZ(i) => Some((Axis::Z, i)),
                _ => None,
            };
            match (single(&ops[k]), ops.get(k + 1).and_then(single)) {
                (Some((a, i)), Some((b, j))) => {
                    fused.push(match (a, b) {
                        (Axis::X, Axis::X) => Op::ErrXX(i, j),
                        (Axis::X, Axis::Y) => Op::ErrXY(i, j),
                        (Axis::X, Axis::Z) => Op::ErrXZ(i, j),
                        (Axis::Y, Axis::X) => Op::ErrYX(i, j),
                        (Axis::Y, Axis::Y) => Op::ErrYY(i, j),
                        (Axis::Y, Axis::Z) => Op::ErrYZ(i, j),
                        (Axis::Z, Axis::X) => Op::ErrZX(i, j),
                        (Axis::Z, Axis::Y) => Op::ErrZY(i, j),
                        (Axis::Z, Axis::Z) => Op::ErrZZ(i, j),
                    });
                    k += 2;
                }
                _ => {
                    fused.push(ops[k]);
                    k += 1;
                }
            }
        }
        let ops = fused;
        Self {
            ops,
            chi_sign,
            free,
            fixed,
            n_joints: turntable.n_joints(),
        }
    }

    /// `[dpsi, dtheta, dgamma]` (rad) for one sample: `pose_rad` every joint, `chi_rad` the
    /// angular errors; error half-angles by [`half_sin_cos`], joints by `f64::sin_cos`.
    fn evaluate(&self, pose_rad: &[f64], chi_rad: &[f64]) -> [f64; 3] {
        let mut q = [1.0, 0.0, 0.0, 0.0];
        for op in &self.ops {
            let err = |i: usize| {
                let (s, c) = half_sin_cos(chi_rad[i]);
                (self.chi_sign[i] * s, c)
            };
            let joint = |k: usize| match self.free.get(k) {
                Some(f) => {
                    let (s, c) = pose_rad[f.joint].sin_cos();
                    (f.sign * s, c)
                }
                None => self.fixed[k - self.free.len()],
            };
            q = match *op {
                Op::Init2(pair, i, j) => {
                    let (a, b) = match pair {
                        Pair::Xy => (Axis::X, Axis::Y),
                        Pair::Xz => (Axis::X, Axis::Z),
                        Pair::Yx => (Axis::Y, Axis::X),
                        Pair::Yz => (Axis::Y, Axis::Z),
                        Pair::Zx => (Axis::Z, Axis::X),
                        Pair::Zy => (Axis::Z, Axis::Y),
                    };
                    let ((sa, ca), (sb, cb)) = (err(i), err(j));
                    quat_mul_axis(quat_mul_axis(q, a, sa, ca), b, sb, cb)
                }
                Op::ErrXX(i, j)
                | Op::ErrXY(i, j)
                | Op::ErrXZ(i, j)
                | Op::ErrYX(i, j)
                | Op::ErrYY(i, j)
                | Op::ErrYZ(i, j)
                | Op::ErrZX(i, j)
                | Op::ErrZY(i, j)
                | Op::ErrZZ(i, j) => {
                    let (a, b) = match *op {
                        Op::ErrXX(..) => (Axis::X, Axis::X),
                        Op::ErrXY(..) => (Axis::X, Axis::Y),
                        Op::ErrXZ(..) => (Axis::X, Axis::Z),
                        Op::ErrYX(..) => (Axis::Y, Axis::X),
                        Op::ErrYY(..) => (Axis::Y, Axis::Y),
                        Op::ErrYZ(..) => (Axis::Y, Axis::Z),
                        Op::ErrZX(..) => (Axis::Z, Axis::X),
                        Op::ErrZY(..) => (Axis::Z, Axis::Y),
                        _ => (Axis::Z, Axis::Z),
                    };
                    let ((sa, ca), (sb, cb)) = (err(i), err(j));
                    quat_mul_axis(quat_mul_axis(q, a, sa, ca), b, sb, cb)
                }
                Op::InitX(i) | Op::ErrX(i) => {
                    let (s, c) = err(i);
                    quat_mul_axis(q, Axis::X, s, c)
                }
                Op::InitY(i) | Op::ErrY(i) => {
                    let (s, c) = err(i);
                    quat_mul_axis(q, Axis::Y, s, c)
                }
                Op::InitZ(i) | Op::ErrZ(i) => {
                    let (s, c) = err(i);
                    quat_mul_axis(q, Axis::Z, s, c)
                }
                Op::JointX(k) => {
                    let (s, c) = joint(k);
                    quat_conjugate_axis(q, Axis::X, s, c)
                }
                Op::JointY(k) => {
                    let (s, c) = joint(k);
                    quat_conjugate_axis(q, Axis::Y, s, c)
                }
                Op::JointZ(k) => {
                    let (s, c) = joint(k);
                    quat_conjugate_axis(q, Axis::Z, s, c)
                }
            };
        }
        quat_readout(q)
    }
}

/// How a free joint's sine and cosine are computed from its word.
#[derive(Debug, Clone, Copy, PartialEq)]
enum JointTrig {
    /// Full turn: [`sin_cos_turn`] of the word.
    Turn,
    /// Ranged joint within $\pm$ `REDUCTION_MAX_ABS_RAD`: [`sin_cos_reduced`] of the angle.
    Reduced(JointLaw),
    /// Any other range: `f64::sin_cos` of the angle.
    Libm(JointLaw),
}

/// A free joint as the block kernel evaluates it.
#[derive(Debug, Clone, Copy, PartialEq)]
struct JointColumn {
    /// Word column of the joint in a block.
    column: usize,
    trig: JointTrig,
    sign: f64,
}

/// Per-chunk buffers of [`PlanKernel`].
pub(crate) struct PlanScratch {
    /// $\sin\tfrac x2$ (or $\tan\tfrac x2$) per angular error, sign folded in.
    s: Vec<Col>,
    /// $\cos\tfrac x2$ per angular error (unit-quaternion tiers; empty in the tangent tier).
    c: Vec<Col>,
    /// $\sin\phi$ per rotation slot (free joints, sign folded in; then the fixed
    /// rotations, constant).
    js: Vec<Col>,
    /// $\cos\phi$ per rotation slot.
    jc: Vec<Col>,
}

/// The compiled plan of a run with its tier's coefficients: the block kernel of
/// [`crate::MonteCarlo::run`].
#[derive(Debug, Clone)]
pub(crate) struct PlanKernel<'a, const TIER: u8> {
    plan: &'a CompiledPlan,
    sampler: &'a TurntableSampler,
    /// Tangent tier: $(\pm s/2, \pm s^3/24)$ per angular error.
    tan: Vec<[f64; 2]>,
    joints: Vec<JointColumn>,
    table: &'static TurnTable,
}

impl<'a, const TIER: u8> PlanKernel<'a, TIER> {
    pub(crate) fn new(plan: &'a CompiledPlan, sampler: &'a TurntableSampler) -> Self {
        let tan = sampler
            .scale_rad()
            .iter()
            .zip(&plan.chi_sign)
            .map(|(&s, &sign)| [sign * (0.5 * s), sign * (s * s * s / 24.0)])
            .collect();
        let n_chi = sampler.n_rotation_errors();
        let joints = plan
            .free
            .iter()
            .map(|f| {
                let law = sampler.joint_laws()[f.joint];
                let trig = match law {
                    JointLaw::FullTurn => JointTrig::Turn,
                    JointLaw::Range { lo_rad, hi_rad, .. }
                        if lo_rad.abs().max(hi_rad.abs()) <= REDUCTION_MAX_ABS_RAD =>
                    {
                        JointTrig::Reduced(law)
                    }
                    JointLaw::Range { .. } => JointTrig::Libm(law),
                };
                JointColumn {
                    column: n_chi + f.joint,
                    trig,
                    sign: f.sign,
                }
            })
            .collect();
        Self {
            plan,
            sampler,
            tan,
            joints,
            table: turn_table(),
        }
    }

    /// Pass 1 and 2: the error and joint columns of the `n` samples of `block`.
    #[inline(always)]
    fn prepare(&self, block: &SampleBlock, n: usize, scratch: &mut PlanScratch) {
        self.prepare_errors(block, n, scratch);
        self.prepare_joints(block, n, scratch);
    }

    /// Pass 1: per angular error, $\tan\tfrac x2$ (tangent tier) or $(\sin\tfrac x2,
    /// \cos\tfrac x2)$ from the words.
    #[inline(always)]
    fn prepare_errors(&self, block: &SampleBlock, n: usize, scratch: &mut PlanScratch) {
        let PlanScratch { s, c, .. } = scratch;
        if TIER == TIER_TANGENT {
            for (i, s_col) in s.iter_mut().enumerate() {
                let [k0, k1] = self.tan[i];
                for (x, w) in s_col.as_flattened_mut()[..n]
                    .iter_mut()
                    .zip(block.column_words(i))
                {
                    let t = f64::from(w as i32) + 0.5;
                    *x = t * (k0 + (t * t) * k1);
                }
            }
        } else {
            for (i, (s_col, c_col)) in s.iter_mut().zip(c.iter_mut()).enumerate() {
                let s_col = &mut s_col.as_flattened_mut()[..n];
                self.sampler.decode_chi(i, block.column_words(i), s_col);
                let sign = self.plan.chi_sign[i];
                for (x, co) in s_col.iter_mut().zip(&mut c_col.as_flattened_mut()[..n]) {
                    let (sn, cs) = half_sin_cos_tier::<TIER>(*x);
                    *x = sign * sn;
                    *co = cs;
                }
            }
        }
    }

    /// Pass 2: per free joint, $(\sin\phi, \cos\phi)$ from the words.
    #[inline(always)]
    fn prepare_joints(&self, block: &SampleBlock, n: usize, scratch: &mut PlanScratch) {
        let PlanScratch { js, jc, .. } = scratch;
        for ((j, s_col), c_col) in self.joints.iter().zip(js.iter_mut()).zip(jc.iter_mut()) {
            let pairs = s_col.as_flattened_mut()[..n]
                .iter_mut()
                .zip(&mut c_col.as_flattened_mut()[..n])
                .zip(block.column_words(j.column));
            // Two passes for the table methods: a scalar one fetches the table entries (a
            // lookup per sample does not vectorise), then a vectorised one computes the
            // remainder's series and the angle-sum formula: per sample exactly the arithmetic
            // of `sin_cos_turn_with` / `sin_cos_reduced`.
            match j.trig {
                JointTrig::Turn => {
                    for ((s, c), w) in pairs {
                        (*s, *c) = table_entry(self.table, turn_index(w));
                    }
                    let pairs = s_col.as_flattened_mut()[..n]
                        .iter_mut()
                        .zip(&mut c_col.as_flattened_mut()[..n])
                        .zip(block.column_words(j.column));
                    for ((s, c), w) in pairs {
                        let (sn, cs) = rotate_entry((*s, *c), turn_remainder(w));
                        (*s, *c) = (j.sign * sn, cs);
                    }
                }
                JointTrig::Reduced(law) => {
                    for ((s, c), w) in pairs {
                        (*s, *c) = table_entry(self.table, reduced_index(law.angle(w)).0);
                    }
                    let pairs = s_col.as_flattened_mut()[..n]
                        .iter_mut()
                        .zip(&mut c_col.as_flattened_mut()[..n])
                        .zip(block.column_words(j.column));
                    for ((s, c), w) in pairs {
                        let a = law.angle(w);
                        let d = a - reduced_index(a).1 * (TAU / TURN_TABLE_LEN as f64);
                        let (sn, cs) = rotate_entry((*s, *c), d);
                        (*s, *c) = (j.sign * sn, cs);
                    }
                }
                JointTrig::Libm(law) => {
                    for ((s, c), w) in pairs {
                        let (sn, cs) = law.angle(w).sin_cos();
                        (*s, *c) = (j.sign * sn, cs);
                    }
                }
            }
        }
    }

    /// Pass 3: the operations on lanes of samples, and the read-out.
    #[inline(always)]
    fn lanes(&self, n: usize, scratch: &PlanScratch, out: &mut [[f64; BLOCK_CAPACITY]; 3]) {
        const L: usize = LANES;
        let tangent = TIER == TIER_TANGENT;
        let PlanScratch { s, c, js, jc } = scratch;
        let groups = n.div_ceil(L).min(GROUPS);
        for g in 0..groups {
            // (sin, cos) of error column i in this lane group (tangent tier: (tan, unused))
            let sc = |i: usize| -> (&[f64; L], &[f64; L]) {
                if tangent {
                    (&s[i][g], &s[i][g])
                } else {
                    (&s[i][g], &c[i][g])
                }
            };
            let mut q = [[1.0; L], [0.0; L], [0.0; L], [0.0; L]];
            for op in &self.plan.ops {
                macro_rules! rot {
                    ($axis:expr, $i:expr) => {{
                        let (si, ci) = sc($i);
                        rotate::<{ $axis }, TIER>(&mut q, si, ci);
                    }};
                }
                match *op {
                    Op::InitX(i) | Op::InitY(i) | Op::InitZ(i) => {
                        let (si, ci) = sc(i);
                        let w = if tangent { [1.0; L] } else { *ci };
                        let zero = [0.0; L];
                        q = match *op {
                            Op::InitX(_) => [w, *si, zero, zero],
                            Op::InitY(_) => [w, zero, *si, zero],
                            _ => [w, zero, zero, *si],
                        };
                    }
                    Op::Init2(pair, i, j) => {
                        let ((sa, ca), (sb, cb)) = (sc(i), sc(j));
                        // (c_a c_b, s_a c_b e_A + c_a s_b e_B + s_a s_b e_A x e_B)
                        let (q_w, q_a, q_b) = if tangent {
                            ([1.0; L], *sa, *sb)
                        } else {
                            (
                                std::array::from_fn(|l| ca[l] * cb[l]),
                                std::array::from_fn(|l| sa[l] * cb[l]),
                                std::array::from_fn(|l| ca[l] * sb[l]),
                            )
                        };
                        let q_c: [f64; L] = std::array::from_fn(|l| sa[l] * sb[l]);
                        let neg_c: [f64; L] = std::array::from_fn(|l| -q_c[l]);
                        q = match pair {
                            Pair::Xy => [q_w, q_a, q_b, q_c],
                            Pair::Xz => [q_w, q_a, neg_c, q_b],
                            Pair::Yx => [q_w, q_b, q_a, neg_c],
                            Pair::Yz => [q_w, q_c, q_a, q_b],
                            Pair::Zx => [q_w, q_b, q_c, q_a],
                            Pair::Zy => [q_w, neg_c, q_b, q_a],
                        };
                    }
                    Op::ErrX(i) => rot!(AX_X, i),
                    Op::ErrY(i) => rot!(AX_Y, i),
                    Op::ErrZ(i) => rot!(AX_Z, i),
                    Op::ErrXX(i, j) => {
                        rot!(AX_X, i);
                        rot!(AX_X, j);
                    }
                    Op::ErrXY(i, j) => {
                        rot!(AX_X, i);
                        rot!(AX_Y, j);
                    }
                    Op::ErrXZ(i, j) => {
                        rot!(AX_X, i);
                        rot!(AX_Z, j);
                    }
                    Op::ErrYX(i, j) => {
                        rot!(AX_Y, i);
                        rot!(AX_X, j);
                    }
                    Op::ErrYY(i, j) => {
                        rot!(AX_Y, i);
                        rot!(AX_Y, j);
                    }
                    Op::ErrYZ(i, j) => {
                        rot!(AX_Y, i);
                        rot!(AX_Z, j);
                    }
                    Op::ErrZX(i, j) => {
                        rot!(AX_Z, i);
                        rot!(AX_X, j);
                    }
                    Op::ErrZY(i, j) => {
                        rot!(AX_Z, i);
                        rot!(AX_Y, j);
                    }
                    Op::ErrZZ(i, j) => {
                        rot!(AX_Z, i);
                        rot!(AX_Z, j);
                    }
                    Op::JointX(k) => conjugate::<AX_X>(&mut q, &js[k][g], &jc[k][g]),
                    Op::JointY(k) => conjugate::<AX_Y>(&mut q, &js[k][g], &jc[k][g]),
                    Op::JointZ(k) => conjugate::<AX_Z>(&mut q, &js[k][g], &jc[k][g]),
                }
            }
            let [o0, o1, o2] = out;
            let [w, x, y, z] = q;
            for l in 0..L {
                let k = g * L + l;
                let (w, x, y, z) = (w[l], x[l], y[l], z[l]);
                if tangent {
                    // read-out of the unit quaternion q~/|q~|
                    let r = 2.0 / ((w * w + x * x) + (y * y + z * z));
                    o0[k] = r * (x * z + w * y);
                    o1[k] = r * (x * y + w * z);
                    o2[k] = r * (y * z + w * x);
                } else {
                    o0[k] = 2.0 * (x * z + w * y);
                    o1[k] = 2.0 * (x * y + w * z);
                    o2[k] = 2.0 * (y * z + w * x);
                }
            }
        }
    }
}

/// Axis codes of the const-generic lane operations.
const AX_X: u8 = 0;
const AX_Y: u8 = 1;
const AX_Z: u8 = 2;

/// Lanes of quaternions, component-major: `q[0]` the $w$ of every lane, then $x, y, z$.
type LaneQuats = [[f64; LANES]; 4];

/// $q \leftarrow q \otimes (c, s\,\hat e_{\text{AXIS}})$ per lane, the formulas of
/// [`tt_kinematics::quat_mul_axis`]; in the tangent tier $c = 1$ is not multiplied (`c` is
/// not read).
#[inline(always)]
fn rotate<const AXIS: u8, const TIER: u8>(q: &mut LaneQuats, s: &[f64; LANES], c: &[f64; LANES]) {
    let [w, x, y, z] = q;
    for l in 0..LANES {
        let (w0, x0, y0, z0, s) = (w[l], x[l], y[l], z[l], s[l]);
        (w[l], x[l], y[l], z[l]) = if TIER == TIER_TANGENT {
            match AXIS {
                AX_X => (w0 - x0 * s, w0 * s + x0, y0 + z0 * s, z0 - y0 * s),
                AX_Y => (w0 - y0 * s, x0 - z0 * s, w0 * s + y0, x0 * s + z0),
                _ => (w0 - z0 * s, x0 + y0 * s, y0 - x0 * s, w0 * s + z0),
            }
        } else {
            let c = c[l];
            match AXIS {
                AX_X => (
                    w0 * c - x0 * s,
                    w0 * s + x0 * c,
                    y0 * c + z0 * s,
                    z0 * c - y0 * s,
                ),
                AX_Y => (
                    w0 * c - y0 * s,
                    x0 * c - z0 * s,
                    w0 * s + y0 * c,
                    x0 * s + z0 * c,
                ),
                _ => (
                    w0 * c - z0 * s,
                    x0 * c + y0 * s,
                    y0 * c - x0 * s,
                    w0 * s + z0 * c,
                ),
            }
        };
    }
}

/// $q \leftarrow n^{-1} \otimes q \otimes n$ per lane for the rotation $n$ about `AXIS` with
/// sine `s` and cosine `c` (the formulas of [`tt_kinematics::quat_conjugate_axis`]).
#[inline(always)]
fn conjugate<const AXIS: u8>(q: &mut LaneQuats, s: &[f64; LANES], c: &[f64; LANES]) {
    let [_, x, y, z] = q;
    for l in 0..LANES {
        let (s, c) = (s[l], c[l]);
        match AXIS {
            AX_X => (y[l], z[l]) = (c * y[l] + s * z[l], c * z[l] - s * y[l]),
            AX_Y => (x[l], z[l]) = (c * x[l] - s * z[l], s * x[l] + c * z[l]),
            _ => (x[l], y[l]) = (c * x[l] + s * y[l], c * y[l] - s * x[l]),
        }
    }
}

/// The per-block work of a fast path. Every method is `#[inline(always)]` in every
/// implementation so that it is compiled into the loop of each SIMD level (a closure would be
/// compiled once, for the portable level, and called per sample).
pub(crate) trait BlockKernel: Sync {
    /// Per-chunk buffers.
    type Scratch;
    /// Fresh buffers (allocated once per chunk).
    fn scratch(&self) -> Self::Scratch;
    /// `out[k][..n]`: angle `k` (`dpsi`, `dtheta`, `dgamma`, rad) of the `n` samples of
    /// `block`.
    fn eval_block(
        &self,
        block: &SampleBlock,
        n: usize,
        scratch: &mut Self::Scratch,
        out: &mut [[f64; BLOCK_CAPACITY]; 3],
    );
}

impl<const TIER: u8> BlockKernel for PlanKernel<'_, TIER> {
    type Scratch = PlanScratch;

    fn scratch(&self) -> PlanScratch {
        let n_chi = self.sampler.n_rotation_errors();
        let col = [[0.0; LANES]; GROUPS];
        let mut js = vec![col; self.joints.len()];
        let mut jc = js.clone();
        // the fixed rotations' slots: constant columns, written once
        for &(sn, cs) in &self.plan.fixed {
            js.push([[sn; LANES]; GROUPS]);
            jc.push([[cs; LANES]; GROUPS]);
        }
        // the tangent tier reads no cosines
        let n_cos = if TIER == TIER_TANGENT { 0 } else { n_chi };
        PlanScratch {
            s: vec![col; n_chi],
            c: vec![col; n_cos],
            js,
            jc,
        }
    }

    #[inline(always)]
    fn eval_block(
        &self,
        block: &SampleBlock,
        n: usize,
        scratch: &mut PlanScratch,
        out: &mut [[f64; BLOCK_CAPACITY]; 3],
    ) {
        self.prepare(block, n, scratch);
        self.lanes(n, scratch, out);
    }
}

/// The exact chain of any turntable with the eq-24 read-out, evaluated by its compiled plan
/// (unit quaternions, error half-angles by the series or `f64::sin_cos`, joints by
/// `f64::sin_cos`): a drop-in [`OrientationErrorModel`] equal to
/// [`tt_kinematics::ExactChain`] to rounding (error translations have no effect on the
/// orientation).
///
/// ```
/// use mc_verify::FastChain;
/// use tt_kinematics::{paper, ExactChain, OrientationErrorModel, Pose, TurntableErrors};
/// let table = paper::table3();
/// let pose = Pose::from_deg(&[10.0, 20.0])?;
/// let errors = TurntableErrors::from_arcmin(&[0.4, 0.8, 0.4, 0.8, 0.3, 0.3, 0.4, 0.4], &[0.0])?;
/// let fast = FastChain::new(&table).orientation_error(&pose, &errors)?;
/// let plain = ExactChain::new(&table).orientation_error(&pose, &errors)?;
/// assert!((fast.delta_psi_rad - plain.delta_psi_rad).abs() < 1e-15);
/// # Ok::<(), tt_kinematics::KinematicsError>(())
/// ```
///
/// # Reference
/// Paper eq 17-25.
#[derive(Debug, Clone, PartialEq)]
pub struct FastChain {
    plan: CompiledPlan,
    names: Vec<String>,
    n_chi: usize,
    n_translations: usize,
}

impl FastChain {
    /// The fast exact chain of `turntable`.
    #[must_use]
    pub fn new(turntable: &Turntable) -> Self {
        Self {
            plan: CompiledPlan::new(turntable),
            names: turntable
                .rotation_error_names()
                .into_iter()
                .map(str::to_string)
                .collect(),
            n_chi: turntable.n_rotation_errors(),
            n_translations: turntable.n_translation_errors(),
        }
    }
}

impl OrientationErrorModel for FastChain {
    fn error_names(&self) -> Vec<String> {
        self.names.clone()
    }

    fn orientation_error(
        &self,
        pose: &Pose,
        errors: &TurntableErrors,
    ) -> Result<OrientationError, KinematicsError> {
        let check = tt_core::length;
        check("pose", self.plan.n_joints, pose.len())?;
        check("chi", self.n_chi, errors.chi_rad().len())?;
        check(
            "translations",
            self.n_translations,
            errors.translations_m().len(),
        )?;
        Ok(OrientationError::from_array(
            self.plan.evaluate(pose.angles_rad(), errors.chi_rad()),
        ))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sampler::chunk_rng;
    use proptest::prelude::*;
    use tt_kinematics::{ExactChain, paper};

    /// Fast paths against the plain chain, rad (the issue's per-sample bound).
    const FAST_VS_PLAIN_ABS_RAD: f64 = 1e-15;

    proptest! {
        /// The unnormalised-quaternion kernel of the tangent tier, from the words'
        /// half-integers, equals the plain chain (eq 17-24) within 1e-15 rad for any box
        /// inside the short range and any words (the paper's table).
        #[test]
        fn tangent_kernel_from_words_equals_plain_chain(
            ub in proptest::array::uniform8(0.0..=SHORT_SERIES_MAX_ABS_RAD),
            seed in any::<u64>(),
        ) {
            let table = paper::table3();
            let bounds = ErrorBox::from_upper_rad(&table, ub.to_vec()).unwrap();
            prop_assert_eq!(Tier::for_box(&bounds), Tier::Tangent);
            let sampler = TurntableSampler::new(&bounds, &table);
            let plan = CompiledPlan::new(&table);
            let kernel = PlanKernel::<TIER_TANGENT>::new(&plan, &sampler);
            let mut block = SampleBlock::new(&sampler);
            sampler.fill_block(&mut chunk_rng(seed, 0), 13, &mut block);
            let mut scratch = kernel.scratch();
            let mut out = [[0.0; BLOCK_CAPACITY]; 3];
            kernel.eval_block(&block, 13, &mut scratch, &mut out);
            let chain = ExactChain::new(&table);
            let plain: Vec<[f64; 3]> = (0..13)
                .map(|k| {
                    let errors = TurntableErrors::new(block.chi_rad(k), vec![0.0]).unwrap();
                    chain.orientation_error(&block.pose(k), &errors).unwrap().to_array()
                })
                .collect();
            for (a, fast) in out.iter().enumerate() {
                for (k, (f, p)) in fast.iter().zip(&plain).enumerate() {
                    prop_assert!((f - p[a]).abs() <= FAST_VS_PLAIN_ABS_RAD,
                        "sample {k} axis {a}: fast {f} plain {}", p[a]);
                }
            }
        }
    }
}
