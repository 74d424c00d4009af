//! The end-to-end linearisation as alloc-opt's [`LinearErrorModel`]: the quantities are the
//! sensor's outputs, the domain the schedule's positions, the coefficients the rows of
//! $\mathbf M$ ([`Linearization::matrix`]). So every allocator of alloc-opt (and an outside
//! one) allocates against the calibration accuracies themselves, with alloc-opt's certificate.

use crate::linear::Linearization;
use alloc_opt::{AllocError, LinearErrorModel, WorstRow};
use nalgebra::DMatrix;

/// Below this share of the largest $|M|$ a column is no dependence (as
/// [`Linearization::unconstrained`]).
const NO_DEPENDENCE_REL: f64 = 1e-12;

impl LinearErrorModel for Linearization {
    fn n_errors(&self) -> usize {
        self.matrix().ncols()
    }

    fn n_quantities(&self) -> usize {
        self.outputs()
    }

    /// [`Linearization::output_name`].
    fn quantity_name(&self, k: usize) -> String {
        self.output_name(k)
    }

    /// [`Linearization::error_name`].
    fn error_name(&self, j: usize) -> String {
        Linearization::error_name(self, j)
    }

    /// The errors output `k` depends on: some entry of its rows above both
    /// $10^{-12}\max|M|$ and its rounding level ([`Linearization::rounding`]).
    fn involved(&self, k: usize) -> Vec<usize> {
        let m = self.matrix();
        let (n, top) = (self.positions(), m.amax());
        (0..m.ncols())
            .filter(|&j| {
                let a = m.view((k * n, j), (n, 1)).amax();
                a > NO_DEPENDENCE_REL * top && a > self.rounding()[(k, j)]
            })
            .collect()
    }

    /// $\max_i \sum_j w_j |M_{(k,i),j}|$ over the positions $i$: exact (a finite domain).
    fn worst_case(&self, k: usize, w: &[f64]) -> Result<WorstRow, AllocError> {
        tt_core::length("weights", self.matrix().ncols(), w.len())?;
        let n = self.positions();
        let mut best = (0, f64::NEG_INFINITY);
        for i in 0..n {
            let v: f64 = self
                .matrix()
                .row(self.row_index(k, i))
                .iter()
                .zip(w)
                .map(|(m, u)| m.abs() * u)
                .sum();
            if v > best.1 {
                best = (i, v);
            }
        }
        let row = self
            .row(k, best.0)
            .into_iter()
            .map(f64::abs)
            .collect::<Vec<_>>();
        Ok(WorstRow::exact(best.1, vec![best.0 as f64], row).with_tag(best.0 as f64))
    }

    /// The mean over the positions of $|M_{(k,i),j}|$.
    fn average_abs_coefficients(&self) -> DMatrix<f64> {
        let (n, m) = (self.positions(), self.matrix());
        DMatrix::from_fn(self.outputs(), m.ncols(), |k, j| {
            m.view((k * n, j), (n, 1))
                .iter()
                .map(|v| v.abs())
                .sum::<f64>()
                / n as f64
        })
    }

    /// Every position's row, as the exchange method's start.
    fn start_rows(&self, k: usize) -> Vec<WorstRow> {
        (0..self.positions())
            .map(|i| {
                let row = self.row(k, i).into_iter().map(f64::abs).collect();
                WorstRow::exact(f64::NAN, vec![i as f64], row).with_tag(i as f64)
            })
            .collect()
    }
}
