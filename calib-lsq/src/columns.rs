//! The fast path of the two readings a Monte Carlo runs millions of times, on input values laid
//! out as columns.
//!
//! # Layout
//! [`InputColumns`] holds the six input values ($a_x, a_y, a_z, \omega_x, \omega_y, \omega_z$)
//! of every position as six columns (structure of arrays) after a column of ones, each padded
//! to a whole number of [`POSITION_LANES`] positions. A term of the sensor model over every
//! position is then one loop over contiguous columns, which the compiler vectorises, with no
//! transposition between the turntable's chain (which produces positions side by side,
//! e2e-verify's kernel) and the calibration.
//!
//! # Same bits as the generic path
//! Every sum runs term by term from $-0$ in column order, every monomial multiplies its
//! factors from $1$ in input order, and every product keeps the generic path's grouping
//! (a factor $1$ is not multiplied: $x\cdot 1 = x$ exactly). Only the positions go side by side,
//! so each position's result has the bits of the per-position evaluation (tested here and in
//! [`crate::analysis`]). The caller may compile these loops for wider vectors (e2e-verify runs
//! them inside `mc_verify::simd`'s AVX2 dispatch): Rust forms no fused multiply-add on its
//! own, so the bits stay the same.

use crate::analysis::{ErrorForm, ErrorWork, Estimate, OutputsAt, Reading};
use crate::calibration::{OutputCalibration, QuadraticTerms};
use crate::error::CalibError;
use gw_model::InputValues;

/// Positions whose prediction $\mathbf A\hat{\boldsymbol\beta}_1$ goes side by side, and the
/// columns' padding. Eight: each sum is a chain of dependent additions, and eight positions
/// give the processor several independent vector chains (four gave two, latency-bound).
pub(crate) const POSITION_LANES: usize = 8;

/// Estimated coefficients whose sums $\hat{\boldsymbol\beta}_1 = \mathbf A^+\mathbf y$
/// advance in fixed-size accumulators (outputs with more take the slice path).
pub(crate) const COEFFICIENT_LANES: usize = 8;

/// The six input values of every position as columns, each padded with zeros to a whole
/// number of [`POSITION_LANES`] positions, after a column of ones (entry 0 of
/// $(1, \mathbf v)$, which a monomial's pair may index; see the [module](self)). Filled by a
/// caller's own fast chain (the end-to-end Monte Carlo) or from [`InputValues`]; read by
/// [`OutputCalibration::error_vector_columns`].
#[doc(hidden)]
#[derive(Debug, Clone, Default, PartialEq)]
pub struct InputColumns {
    n: usize,
    stride: usize,
    data: Vec<f64>,
}

impl InputColumns {
    /// Zero input values for `n` positions.
    #[must_use]
    pub fn new(n: usize) -> Self {
        let stride = n.div_ceil(POSITION_LANES) * POSITION_LANES;
        Self {
            n,
            stride,
            data: std::iter::repeat_n(1.0, stride)
                .chain(std::iter::repeat_n(0.0, 6 * stride))
                .collect(),
        }
    }

    /// The number of positions.
    #[must_use]
    pub fn len(&self) -> usize {
        self.n
    }

    /// Whether there is no position.
    #[must_use]
    pub fn is_empty(&self) -> bool {
        self.n == 0
    }

    /// The length of every column: the number of positions rounded up to a whole number of
    /// [`POSITION_LANES`] (a multiple of 4 and of 8).
    #[must_use]
    pub(crate) fn stride(&self) -> usize {
        self.stride
    }

    /// Column `q` (input value `q` of every position, then the padding), [`Self::stride`]
    /// long; empty for `q` >= 6.
    #[must_use]
    pub(crate) fn column(&self, q: usize) -> &[f64] {
        if q < 6 {
            self.extended(q as u8 + 1)
        } else {
            &[]
        }
    }

    /// Column `q` to write, [`Self::stride`] long; empty for `q` >= 6.
    pub fn column_mut(&mut self, q: usize) -> &mut [f64] {
        let s = self.stride;
        match q {
            0..6 => self
                .data
                .get_mut((q + 1) * s..(q + 2) * s)
                .unwrap_or_default(),
            _ => &mut [],
        }
    }

    /// The input values of position `i` (zeros past the last position).
    #[must_use]
    pub fn value(&self, i: usize) -> InputValues {
        InputValues(std::array::from_fn(|q| {
            self.column(q).get(i).copied().unwrap_or(0.0)
        }))
    }

    /// Lay out `values` (one per position), resizing for their number.
    pub(crate) fn set_values(&mut self, values: &[InputValues]) {
        if self.n != values.len() {
            *self = Self::new(values.len());
        }
        for q in 0..6 {
            for (c, v) in self.column_mut(q).iter_mut().zip(values) {
                *c = v.0[q];
            }
        }
    }

    /// The six columns to write, each [`Self::stride`] long.
    pub fn columns_mut(&mut self) -> [&mut [f64]; 6] {
        let mut columns = self.data.chunks_exact_mut(self.stride.max(1)).skip(1);
        std::array::from_fn(|_| columns.next().unwrap_or_default())
    }

    /// Entry `i` of $(1, \mathbf v)$ at every position (the padding's too): ones for 0, input
    /// value $i - 1$ otherwise (the index of a monomial's pair, [`QuadraticTerms`]); empty
    /// past 6.
    #[inline(always)]
    fn extended(&self, i: u8) -> &[f64] {
        let (i, s) = (usize::from(i), self.stride);
        self.data.get(i * s..(i + 1) * s).unwrap_or_default()
    }
}

impl OutputCalibration {
    /// Whether [`OutputCalibration::error_vector_columns`] evaluates `reading` on the columns
    /// themselves (the paper's reading for any output; the user's reading, [`Reading::USER`],
    /// for an output whose monomials have degree at most 2). For any other reading it copies
    /// the columns into input values first.
    #[must_use]
    pub(crate) fn reads_columns(&self, reading: Reading) -> bool {
        matches!(
            (
                reading.outputs,
                reading.estimate,
                reading.form,
                &self.fast.quadratic
            ),
            (OutputsAt::Intended, Estimate::Beta1, ErrorForm::Printed, _)
                | (
                    OutputsAt::Actual,
                    Estimate::Beta1,
                    ErrorForm::Printed,
                    Some(_)
                )
        )
    }

    /// [`OutputCalibration::error_vector_at`] for input values laid out as columns: the same
    /// error vector, to the bit (see the [module](self)).
    ///
    /// Inlined into the caller (with the fast paths it calls), so that a caller's loop
    /// compiled for wider vectors (`mc_verify::simd`) compiles these for them too.
    ///
    /// # Errors
    /// As [`OutputCalibration::error_vector_at`].
    #[doc(hidden)]
    #[inline(always)]
    pub fn error_vector_columns(
        &self,
        reading: Reading,
        actual: &InputColumns,
        work: &mut ErrorWork,
        out: &mut [f64],
    ) -> Result<(), CalibError> {
        let n = self.check_lengths(actual.len(), out.len())?;
        match (
            reading.outputs,
            reading.estimate,
            reading.form,
            &self.fast.quadratic,
        ) {
            (OutputsAt::Intended, Estimate::Beta1, ErrorForm::Printed, _) => {
                self.intended_beta1_columns(actual, work, out);
                Ok(())
            }
            (OutputsAt::Actual, Estimate::Beta1, ErrorForm::Printed, Some(q)) => {
                self.actual_beta1_columns(q, actual, work, out);
                Ok(())
            }
            _ => {
                let mut values = std::mem::take(&mut work.values);
                values.clear();
                values.extend((0..n).map(|i| actual.value(i)));
                let r = self.error_vector_generic(reading, &values, work, out);
                work.values = values;
                r
            }
        }
    }

    /// The paper's reading ([`Reading::PAPER`]: outputs at the intended orientation,
    /// $\hat{\boldsymbol\beta}_1$, eq 13 as printed): $\mathbf b_1$ and
    /// $\hat{\boldsymbol\beta}_1$ do not depend on the actual inputs, so the error vector is
    /// the precomputed $\mathbf b_1 - \mathbf A\hat{\boldsymbol\beta}_1$ minus $\mathbf b_2'$,
    /// the known terms at the actual inputs (monomials of any degree).
    #[inline(always)]
    fn intended_beta1_columns(&self, actual: &InputColumns, work: &mut ErrorWork, out: &mut [f64]) {
        let f = &self.fast;
        let ErrorWork {
            b2_actual: known,
            y: product,
            ..
        } = work;
        known.clear();
        known.resize(actual.stride(), -0.0);
        product.resize(actual.stride(), 1.0);
        for (c, m) in &f.known {
            product.fill(1.0);
            for &i in m.factors() {
                for (p, x) in product.iter_mut().zip(actual.column(usize::from(i))) {
                    *p *= x;
                }
            }
            for (s, p) in known.iter_mut().zip(product.iter()) {
                *s += c * p;
            }
        }
        for ((o, r), s) in out.iter_mut().zip(&f.intended_residual).zip(known.iter()) {
            *o = r - s;
        }
    }

    /// The user's reading ([`Reading::USER`]: outputs at the actual orientation,
    /// $\hat{\boldsymbol\beta}_1$, eq 13 as printed) of an output whose monomials all have
    /// degree at most 2: $\mathbf b_1 = \mathbf A'\boldsymbol\beta + \mathbf b_2'$ summed
    /// term by term over every position (no regressor rows), the $k$ sums of
    /// $\hat{\boldsymbol\beta}_1 = \mathbf A^+(\mathbf b_1 - \mathbf b_2)$ side by side, then
    /// $(\mathbf b_1 - \mathbf A\hat{\boldsymbol\beta}_1) - \mathbf b_2'$ [`POSITION_LANES`]
    /// positions side by side.
    #[inline(always)]
    fn actual_beta1_columns(
        &self,
        q: &QuadraticTerms,
        actual: &InputColumns,
        work: &mut ErrorWork,
        out: &mut [f64],
    ) {
        let n = out.len();
        let k = q.estimated.len();
        let beta = self.beta().as_slice();
        let b2 = self.b2().as_slice();
        let ErrorWork {
            b1_actual,
            b2_actual,
            y: beta_hat,
            ..
        } = work;
        // every position of the padded columns (the padding's sums are never read); b1 holds
        // A' beta until the known terms are added
        for sums in [&mut *b1_actual, &mut *b2_actual] {
            sums.clear();
            sums.resize(actual.stride(), -0.0);
        }
        add_terms(
            b1_actual,
            actual,
            q.estimated.iter().copied().zip(beta.iter().copied()),
        );
        add_terms(
            b2_actual,
            actual,
            q.known.iter().map(|&(c, pair)| (pair, c)),
        );
        for (b1, b2) in b1_actual.iter_mut().zip(b2_actual.iter()) {
            // b1 = b2' + A' beta (IEEE addition commutes: the generic path's bits)
            *b1 += b2;
        }
        let (b1_actual, b2_actual) = (&b1_actual[..n], &b2_actual[..n]);
        beta_hat.clear();
        if q.pinv_lanes.is_empty() {
            beta_hat.resize(k, -0.0);
            for ((b1, b2), p) in b1_actual
                .iter()
                .zip(b2)
                .zip(q.pinv_cols.chunks_exact(k.max(1)))
            {
                let y = b1 - b2;
                for (acc, p) in beta_hat.iter_mut().zip(p) {
                    *acc += p * y;
                }
            }
        } else {
            // the same sums in fixed-size accumulators the compiler keeps in registers (the
            // padding lanes k.. sum zeros and are dropped)
            let mut acc = [-0.0; COEFFICIENT_LANES];
            let rows = q.pinv_lanes.chunks_exact(COEFFICIENT_LANES);
            for ((b1, b2), p) in b1_actual.iter().zip(b2).zip(rows) {
                let y = b1 - b2;
                for (a, p) in acc.iter_mut().zip(p) {
                    *a += p * y;
                }
            }
            beta_hat.extend_from_slice(acc.get(..k).unwrap_or_default());
        }
        // A beta-hat-1 for POSITION_LANES positions side by side, each sum from -0 in column
        // order, the rows of A laid out lane-contiguous (QuadraticTerms::a_lanes)
        let whole = n / POSITION_LANES * POSITION_LANES;
        let blocks = out[..whole]
            .chunks_exact_mut(POSITION_LANES)
            .zip(b1_actual.chunks_exact(POSITION_LANES))
            .zip(b2_actual.chunks_exact(POSITION_LANES))
            .zip(q.a_lanes.chunks_exact((k * POSITION_LANES).max(1)));
        for (((out, b1), b2), a) in blocks {
            let mut pred = [-0.0; POSITION_LANES];
            for (b, a) in beta_hat.iter().zip(a.chunks_exact(POSITION_LANES)) {
                for (p, a) in pred.iter_mut().zip(a) {
                    *p += a * b;
                }
            }
            for (((o, p), b1), b2) in out.iter_mut().zip(&pred).zip(b1).zip(b2) {
                *o = b1 - p - b2;
            }
        }
        let a_rows = &self.fast.a_rows;
        for (i, ((o, b1), b2)) in out
            .iter_mut()
            .zip(b1_actual)
            .zip(b2_actual)
            .enumerate()
            .skip(whole)
        {
            let row = a_rows.get(i * k..(i + 1) * k).unwrap_or_default();
            let p: f64 = row.iter().zip(beta_hat.iter()).map(|(a, b)| a * b).sum();
            *o = b1 - p - b2;
        }
    }
}

/// Add $c\,m(\mathbf v)$ to `sums` at every position for each (monomial pair, value $c$) of
/// `terms`, term by term: the generic path's $(x y) c$ and $c (x y)$ are the same bits (IEEE
/// multiplication commutes), and a factor 1 is not multiplied ($x \cdot 1 = x$ exactly).
#[inline(always)]
fn add_terms(sums: &mut [f64], actual: &InputColumns, terms: impl Iterator<Item = ([u8; 2], f64)>) {
    for ([a, b], c) in terms {
        let (x, y) = (actual.extended(a), actual.extended(b));
        match (a, b) {
            (0, 0) => sums.iter_mut().for_each(|s| *s += c),
            (_, 0) => {
                for (s, x) in sums.iter_mut().zip(x) {
                    *s += x * c;
                }
            }
            _ => {
                for ((s, x), y) in sums.iter_mut().zip(x).zip(y) {
                    *s += x * y * c;
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::Calibration;

    /// 21 positions (not a whole number of lanes): every value reads back where it was set,
    /// the padding holds zeros, entry 0 of $(1, \mathbf v)$ is ones, and another number of
    /// positions resizes.
    #[test]
    fn columns_hold_the_values_pad_with_zeros_and_lead_with_ones() {
        let values: Vec<InputValues> = (0..21)
            .map(|i| InputValues(std::array::from_fn(|q| (10 * i + q) as f64 + 0.5)))
            .collect();
        let mut c = InputColumns::new(3);
        c.set_values(&values);
        assert_eq!((c.len(), c.stride()), (21, 24));
        for (i, v) in values.iter().enumerate() {
            assert_eq!(c.value(i), *v, "position {i}");
        }
        for q in 0..6 {
            assert_eq!(c.column(q).len(), 24);
            assert_eq!(&c.column(q)[21..], &[0.0; 3], "padding of column {q}");
            assert_eq!(c.extended(q as u8 + 1), c.column(q));
        }
        assert_eq!(c.extended(0), &[1.0; 24]);
        assert!(c.column(6).is_empty() && c.column_mut(6).is_empty());
        assert_eq!(c.value(21), InputValues([0.0; 6]));
        c.set_values(&values[..8]);
        assert_eq!((c.len(), c.stride()), (8, 8));
    }

    /// Every reading from columns gives [`OutputCalibration::error_vector_at`]'s bits (the
    /// two fast readings on the columns, the others through the values), on the paper's
    /// schedule with perturbed inputs; wrong lengths are typed errors.
    #[test]
    fn every_reading_from_columns_equals_the_values_path_bit_for_bit() {
        let cal = Calibration::new(
            &gw_model::paper::gyrowheel(),
            &gw_model::paper::site(),
            &crate::paper::schedule(),
        )
        .expect("the paper's schedule identifies every coefficient");
        for o in cal.outputs() {
            let actual: Vec<InputValues> = o
                .nominal_values()
                .iter()
                .enumerate()
                .map(|(i, v)| {
                    InputValues(std::array::from_fn(|q| {
                        v.0[q] + 1e-4 * ((i * 5 + q) as f64).cos()
                    }))
                })
                .collect();
            let n = actual.len();
            let mut columns = InputColumns::new(n);
            columns.set_values(&actual);
            let mut work = ErrorWork::default();
            for reading in Reading::all() {
                let (mut from_columns, mut from_values) = (vec![0.0; n], vec![0.0; n]);
                o.error_vector_columns(reading, &columns, &mut work, &mut from_columns)
                    .expect("lengths match");
                o.error_vector_at(reading, &actual, &mut work, &mut from_values)
                    .expect("lengths match");
                let bits = |v: &[f64]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
                assert_eq!(bits(&from_columns), bits(&from_values), "{reading}");
            }
            let short = InputColumns::new(n - 1);
            assert!(matches!(
                o.error_vector_columns(Reading::USER, &short, &mut work, &mut vec![0.0; n]),
                Err(CalibError::Field(tt_core::FieldError::Length { .. }))
            ));
        }
    }
}
