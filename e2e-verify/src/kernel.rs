//! The segmented chain of a turntable's static positions laid out [`LANES`] positions side
//! by side: the per-draw part of [`crate::EndToEnd`]'s fast path.
//!
//! # Formula
//! For position $i$ and a nominal input vector $\mathbf v_i$ (specific force or rate),
//! $\Delta\mathbf R_i^T\mathbf v_i$ is, as in
//! [`tt_kinematics::PoseFrames::delta_r_transpose_times_pre`],
//! $\mathbf w \leftarrow \mathbf B_{1,i}\mathbf v_i$ (once per study), then for every error
//! segment $s$: $\mathbf w \leftarrow \mathbf E_s^T\mathbf w$ and, where the nominal block is
//! not the identity, $\mathbf w \leftarrow \mathbf A_{s,i}^T\mathbf w$. The segment rotations
//! $\mathbf E_s(\chi)$ are the same at every position, the blocks differ: here the positions
//! are the lanes of fixed-size arrays (structure of arrays), so the compiler evaluates
//! [`LANES`] positions with vector instructions, and writes them straight into the columns
//! ([`calib_lsq::InputColumns`]) the calibration reads. [`crate::EndToEnd`] runs the chain
//! and the calibration inside `mc_verify::simd`'s dispatch: with AVX2, where the processor
//! has it, the four lanes are one instruction.
//!
//! # Same bits as the per-position chain
//! Every component is evaluated as nalgebra evaluates it:
//! $(\mathbf M^T\mathbf w)_r = (m_{0r}w_0 + m_{1r}w_1) + m_{2r}w_2$ (`tr_mul`, a dot product
//! per column) and $(\mathbf M\mathbf w)_r = (m_{r0}w_0 + m_{r1}w_1) + m_{r2}w_2$ (`gemv`,
//! one column at a time from the first; IEEE addition is commutative), with no fused
//! multiply-add (Rust never contracts, whatever the vector width). Only the lanes change, so
//! the results are the same bits (tested against the per-position chain, and per SIMD level
//! in `tests/simd_levels.rs`).
//!
//! A vector no output reads ([`calib_lsq::OutputCalibration::inputs_used`]: the paper's
//! reading reads the rate only) is not evaluated.

use calib_lsq::InputColumns;
use nalgebra::{Matrix3, Vector3};
use tt_kinematics::TurntableSchedule;

/// Positions evaluated side by side.
pub(crate) const LANES: usize = 4;

/// One value per lane.
type Lanes = [f64; LANES];

/// A 3-vector, one value per lane per component.
type Vec3 = [Lanes; 3];

/// [`LANES`] positions: their $\mathbf B_1\mathbf a_i$, $\mathbf B_1\boldsymbol\omega_i$ and
/// blocks $\mathbf A_s^T$ (row-major entries, one value per lane). A last group short of
/// positions repeats its last position (evaluated, never written out).
#[derive(Debug, Clone)]
struct Group {
    pre: [Vec3; 2],
    blocks: Vec<Option<[Lanes; 9]>>,
}

/// The static positions of a turntable's schedule compiled for [`StaticChain::columns_into`].
#[derive(Debug, Clone)]
pub(crate) struct StaticChain {
    groups: Vec<Group>,
    /// Whether the specific force (`[0]`) and the rate (`[1]`) are evaluated.
    need: [bool; 2],
}

impl StaticChain {
    /// Whether the specific force (`[0]`) and the rate (`[1]`) columns are written.
    pub(crate) fn writes(&self) -> [bool; 2] {
        self.need
    }

    /// Lay out `table`'s positions with their $\mathbf B_1\mathbf a_i$ and
    /// $\mathbf B_1\boldsymbol\omega_i$ (`pre`, one pair per position), evaluating the specific
    /// force and the rate where `need` says. `None` for an empty schedule or when a position's
    /// blocks differ in structure from the first's (then the per-position chain is used).
    pub(crate) fn new(
        table: &TurntableSchedule,
        pre: &[[Vector3<f64>; 2]],
        need: [bool; 2],
    ) -> Option<Self> {
        let frames = table.frames();
        let first = frames.first()?;
        let shape: Vec<bool> = first.blocks_t().iter().map(Option::is_some).collect();
        if frames.len() != pre.len()
            || frames.iter().any(|f| {
                f.blocks_t()
                    .iter()
                    .map(Option::is_some)
                    .ne(shape.iter().copied())
            })
        {
            return None;
        }
        let last = frames.len() - 1;
        let groups = (0..frames.len().div_ceil(LANES))
            .map(|g| {
                let at = |l: usize| (g * LANES + l).min(last);
                let pre = std::array::from_fn(|v| {
                    std::array::from_fn(|c| std::array::from_fn(|l| pre[at(l)][v][c]))
                });
                let blocks = shape
                    .iter()
                    .enumerate()
                    .map(|(s, &some)| {
                        some.then(|| {
                            std::array::from_fn(|e| {
                                std::array::from_fn(|l| {
                                    frames[at(l)].blocks_t()[s].map_or(0.0, |m| m[(e / 3, e % 3)])
                                })
                            })
                        })
                    })
                    .collect();
                Group { pre, blocks }
            })
            .collect();
        Some(Self { groups, need })
    }

    /// The actual inputs $\Delta\mathbf R_i^T\mathbf a_i$ and
    /// $\Delta\mathbf R_i^T\boldsymbol\omega_i$ of every position into the columns `out`
    /// (sized for the positions) for the segment rotations `segments` ($\mathbf E_s$, from
    /// [`tt_kinematics::Turntable::segment_rotations`]): a group's lanes are a contiguous run
    /// of each column. The columns of a vector not needed are not written (no output reads
    /// them, [`calib_lsq::OutputCalibration::inputs_used`]); the lanes past the last position
    /// hold a repeat of it (padding no one reads).
    ///
    /// Inlined into the caller, so that a caller's loop compiled for wider vectors
    /// (`mc_verify::simd`) compiles the chain for them too.
    #[inline(always)]
    pub(crate) fn columns_into(&self, segments: &[Matrix3<f64>], out: &mut InputColumns) {
        let mut columns = out.columns_mut();
        for (g, group) in self.groups.iter().enumerate() {
            let at = g * LANES;
            let mut write = |first: usize, v: &Vec3| {
                for (column, lanes) in columns.iter_mut().skip(first).zip(v) {
                    if let Some(dst) = column
                        .get_mut(at..)
                        .and_then(<[f64]>::first_chunk_mut::<LANES>)
                    {
                        *dst = *lanes;
                    }
                }
            };
            match self.need {
                [true, true] => {
                    let [a, w] = chain(group, segments, group.pre);
                    write(0, &a);
                    write(3, &w);
                }
                [false, true] => write(3, &chain(group, segments, [group.pre[1]])[0]),
                [true, false] => write(0, &chain(group, segments, [group.pre[0]])[0]),
                [false, false] => {}
            }
        }
    }
}

/// The chain of one group for `V` vectors at once (side by side for more independent work).
/// Plain loops, not `array::map` or `array::from_fn`, whose closures the compiler may leave
/// out of line.
#[inline(always)]
fn chain<const V: usize>(group: &Group, segments: &[Matrix3<f64>], pre: [Vec3; V]) -> [Vec3; V] {
    let mut w = pre;
    for (e, block) in segments.iter().zip(&group.blocks) {
        for x in &mut w {
            *x = tr_mul(e, x);
        }
        if let Some(b) = block {
            for x in &mut w {
                *x = mul(b, x);
            }
        }
    }
    w
}

/// $\mathbf E^T\mathbf w$ per lane, component $r$ = $(e_{0r}w_0 + e_{1r}w_1) + e_{2r}w_2$.
#[inline(always)]
fn tr_mul(e: &Matrix3<f64>, w: &Vec3) -> Vec3 {
    let mut out = [[0.0; LANES]; 3];
    for (r, o) in out.iter_mut().enumerate() {
        let (c0, c1, c2) = (e[(0, r)], e[(1, r)], e[(2, r)]);
        for (l, o) in o.iter_mut().enumerate() {
            *o = c0 * w[0][l] + c1 * w[1][l] + c2 * w[2][l];
        }
    }
    out
}

/// $\mathbf M\mathbf w$ per lane for row-major lane entries `m`, component $r$ =
/// $(m_{r0}w_0 + m_{r1}w_1) + m_{r2}w_2$.
#[inline(always)]
fn mul(m: &[Lanes; 9], w: &Vec3) -> Vec3 {
    let mut out = [[0.0; LANES]; 3];
    for (o, m) in out.iter_mut().zip(m.chunks_exact(3)) {
        for (l, o) in o.iter_mut().enumerate() {
            *o = m[0][l] * w[0][l] + m[1][l] * w[1][l] + m[2][l] * w[2][l];
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use gw_model::InputValues;
    use tt_kinematics::{Pose, paper};

    /// The lanes give the per-position chain's bits, for every choice of vectors and a last
    /// group short of positions.
    #[test]
    fn lanes_give_the_per_position_chain_bits() {
        let poses: Vec<Pose> = (0..7)
            .map(|i| Pose::from_deg(&[47.0 * f64::from(i) - 90.0, 0.0 - 33.0 * f64::from(i)]))
            .collect::<Result<_, _>>()
            .unwrap();
        let table = paper::table3();
        let schedule = TurntableSchedule::new(&table, &poses).unwrap();
        let pre: Vec<[Vector3<f64>; 2]> = (0..poses.len())
            .map(|i| {
                let x = i as f64;
                let f = &schedule.frames()[i];
                [
                    f.pre(&Vector3::new(0.1 * x - 0.3, 0.7, -0.2 * x)),
                    f.pre(&Vector3::new(9.0, -3.0 * x, 0.5 + x)),
                ]
            })
            .collect();
        let mut segments = vec![Matrix3::identity(); table.n_segments()];
        for draw in 0..20 {
            let chi: Vec<f64> = (0..table.n_rotation_errors())
                .map(|j| 1e-4 * ((draw * 7 + j * 3) % 11) as f64 - 5e-4)
                .collect();
            table.segment_rotations(&chi, &mut segments).unwrap();
            for need in [[true, true], [false, true], [true, false]] {
                let k = StaticChain::new(&schedule, &pre, need).unwrap();
                let mut out = InputColumns::new(poses.len());
                k.columns_into(&segments, &mut out);
                for (i, (f, [a, w])) in schedule.frames().iter().zip(&pre).enumerate() {
                    let a = f.delta_r_transpose_times_pre(&segments, a);
                    let w = f.delta_r_transpose_times_pre(&segments, w);
                    let expected = InputValues::new(&a, &w).0;
                    for (q, want) in expected.into_iter().enumerate() {
                        let want = if need[q / 3] { want } else { 0.0 };
                        let got = out.value(i).0[q];
                        assert_eq!(got.to_bits(), want.to_bits(), "input {q}, need {need:?}");
                    }
                }
            }
        }
    }
}
