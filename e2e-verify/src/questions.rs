//! The questions an end-to-end answers, one small type per question (issue 33): each is a view
//! of the [`EndToEnd`] it was reached from (`e2e.noise()`, `e2e.rates()`, `e2e.angle()`,
//! `e2e.estimable()`, `e2e.budget()`, `e2e.monte_carlo()`, `e2e.vendor()`) holding the methods that answer that question.
//! [`EndToEnd`] itself keeps construction, the calibration run, the linearisation, the worst
//! case and the entry points. A view dereferences to its end-to-end, so its model, names and
//! linearisation read as before (`e2e.noise().n_errors()`).

use crate::EndToEnd;

/// Defines one question type: a borrowed view of an [`EndToEnd`], `Copy`, dereferencing to it.
macro_rules! question {
    ($(#[$doc:meta])* $name:ident, $accessor:ident) => {
        $(#[$doc])*
        #[derive(Debug)]
        pub struct $name<'a, S = tt_kinematics::TurntableSchedule> {
            e2e: &'a EndToEnd<S>,
        }

        impl<S> Clone for $name<'_, S> {
            fn clone(&self) -> Self {
                *self
            }
        }

        impl<S> Copy for $name<'_, S> {}

        impl<S> std::ops::Deref for $name<'_, S> {
            type Target = EndToEnd<S>;
            fn deref(&self) -> &EndToEnd<S> {
                self.e2e
            }
        }

        impl<S> EndToEnd<S> {
            #[doc = concat!("The [`", stringify!($name), "`] of this end-to-end.")]
            #[must_use]
            pub fn $accessor(&self) -> $name<'_, S> {
                $name { e2e: self }
            }
        }
    };
}

question!(
    /// Both error sources at once ([`crate::noise`]): the sensor's noise budget, the combined
    /// box and yield, the direct allocation that gives the table what the noise leaves, the
    /// dwell/table trade-off, and the noise's sensitivity to its parameters
    /// ([`crate::sensitivity`]). Reached with [`EndToEnd::noise`].
    NoiseQuestions,
    noise
);

question!(
    /// The rate steps' extra errors ([`crate::rate`]): their linearisation, worst case, bounds,
    /// and the allocations of the joint box (with the noise and a certificate). Reached with
    /// [`EndToEnd::rates`].
    RateQuestions,
    rates
);

question!(
    /// The angle-dependent errors ([`crate::angle`], [`crate::disc`]): the expanded
    /// linearisation, its worst case and yield, the compensated and paired allocations.
    /// Reached with [`EndToEnd::angle`].
    AngleQuestions,
    angle
);

question!(
    /// Which table errors a joint least squares estimates from the same data
    /// ([`crate::estimable`]): the joint linearisation, estimate and outputs. Reached with
    /// [`EndToEnd::estimable`].
    EstimableQuestions,
    estimable
);

question!(
    /// The specifications' uncertainty budgets ([`crate::budget`], [`crate::budget_mc`]): the
    /// GUM budget per specification, its rows and verdict, and its JCGM 101 Monte Carlo.
    /// Reached with [`EndToEnd::budget`].
    BudgetQuestions,
    budget
);

question!(
    /// The Monte Carlo over turntables drawn from a box ([`crate::montecarlo`]): the
    /// distribution of every output's error with the yield, the count meeting every accuracy,
    /// the draws themselves and exact order statistics. Reached with [`EndToEnd::monte_carlo`].
    MonteCarloQuestions,
    monte_carlo
);

question!(
    /// The buyer's check of a vendor's tolerances: of a box ([`crate::TurntableCheck`]) and of
    /// a validated [`crate::ToleranceSheet`]. Reached with [`EndToEnd::vendor`].
    VendorQuestions,
    vendor
);
