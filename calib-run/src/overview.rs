//! A recording's overview for a figure: every output's minimum and maximum over a bounded
//! number of consecutive buckets of samples, built while the recording streams by
//! ([`Decimator`]). The length is not known in advance: a bucket starts as one sample, and
//! whenever the buckets reach their cap, neighbours are merged in pairs and every later
//! bucket holds twice as many samples. Memory is the cap's, whatever the recording's length;
//! the extremes are exact (a spike of one sample shows).

/// Buckets of an overview by default (a figure about 1,000 px wide shows them all).
pub const DEFAULT_BUCKETS: usize = 512;

/// The extremes of consecutive samples.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct Bucket {
    /// Time of the first sample, s.
    pub t_first_s: f64,
    /// Time of the last sample, s.
    pub t_last_s: f64,
    /// Every output's minimum (study order, its unit).
    pub min: Vec<f64>,
    /// Every output's maximum.
    pub max: Vec<f64>,
}

impl Bucket {
    fn of(t_s: f64, values: &[f64]) -> Self {
        Self {
            t_first_s: t_s,
            t_last_s: t_s,
            min: values.to_vec(),
            max: values.to_vec(),
        }
    }

    fn absorb(&mut self, other: &Bucket) {
        self.t_last_s = other.t_last_s;
        for (a, b) in self.min.iter_mut().zip(&other.min) {
            *a = a.min(*b);
        }
        for (a, b) in self.max.iter_mut().zip(&other.max) {
            *a = a.max(*b);
        }
    }

    fn push(&mut self, t_s: f64, values: &[f64]) {
        self.t_last_s = t_s;
        for ((lo, hi), v) in self.min.iter_mut().zip(self.max.iter_mut()).zip(values) {
            *lo = lo.min(*v);
            *hi = hi.max(*v);
        }
    }
}

/// The overview of a whole recording.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct Overview {
    samples: u64,
    samples_per_bucket: u64,
    buckets: Vec<Bucket>,
}

impl Overview {
    /// Samples seen.
    #[must_use]
    pub fn samples(&self) -> u64 {
        self.samples
    }

    /// Samples per bucket (the last bucket may hold fewer).
    #[must_use]
    pub fn samples_per_bucket(&self) -> u64 {
        self.samples_per_bucket
    }

    /// The buckets, in time order.
    #[must_use]
    pub fn buckets(&self) -> &[Bucket] {
        &self.buckets
    }
}

/// Builds an [`Overview`] one sample at a time with at most `cap` buckets.
#[derive(Debug, Clone)]
pub struct Decimator {
    cap: usize,
    width: u64,
    samples: u64,
    /// Samples in the last bucket (`width` when it is full).
    in_last: u64,
    buckets: Vec<Bucket>,
}

impl Decimator {
    /// At most `cap` buckets (an even number, at least 2: one merge halves them; an odd cap
    /// is lowered by one).
    #[must_use]
    pub fn new(cap: usize) -> Self {
        let cap = cap.max(2) / 2 * 2;
        Self {
            cap,
            width: 1,
            samples: 0,
            in_last: 0,
            buckets: Vec::with_capacity(cap),
        }
    }

    /// One sample: its time and every output's value.
    pub fn push(&mut self, t_s: f64, values: &[f64]) {
        self.samples += 1;
        if self.in_last > 0 && self.in_last < self.width {
            if let Some(b) = self.buckets.last_mut() {
                b.push(t_s, values);
                self.in_last += 1;
                return;
            }
        }
        if self.buckets.len() == self.cap {
            // every bucket is full (width samples): merge neighbours in pairs, in place, and
            // the new sample opens the next bucket
            let n = self.cap / 2;
            for i in 0..n {
                let right = self.buckets[2 * i + 1].clone();
                self.buckets.swap(i, 2 * i);
                self.buckets[i].absorb(&right);
            }
            self.buckets.truncate(n);
            self.width *= 2;
        }
        self.buckets.push(Bucket::of(t_s, values));
        self.in_last = 1;
    }

    /// The overview.
    #[must_use]
    pub fn finish(self) -> Overview {
        Overview {
            samples: self.samples,
            samples_per_bucket: self.width,
            buckets: self.buckets,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A sample's value: a slow ramp with one spike.
    fn value(i: u64) -> f64 {
        if i == 123_457 {
            50.0
        } else {
            (i % 1000) as f64 * 1e-3
        }
    }

    #[test]
    fn buckets_stay_under_the_cap_and_keep_the_exact_extremes_of_a_long_recording() {
        let cap = 64;
        let mut d = Decimator::new(cap);
        let n: u64 = 1_000_003;
        for i in 0..n {
            let v = value(i);
            d.push(i as f64 * 0.01, &[v, -v]);
            assert!(
                d.buckets.len() <= cap,
                "sample {i}: {} buckets",
                d.buckets.len()
            );
            assert!(
                d.buckets.capacity() <= cap,
                "the buckets' memory grew at sample {i}"
            );
        }
        let o = d.finish();
        assert_eq!(o.samples(), n);
        assert!(o.buckets().len() > cap / 2, "{} buckets", o.buckets().len());
        // every sample in exactly one bucket, in order: the spans tile the recording
        let w = o.samples_per_bucket();
        for (k, b) in o.buckets().iter().enumerate() {
            let first = k as u64 * w;
            let last = (first + w - 1).min(n - 1);
            assert_eq!(
                b.t_first_s.to_bits(),
                (first as f64 * 0.01).to_bits(),
                "bucket {k}"
            );
            assert_eq!(
                b.t_last_s.to_bits(),
                (last as f64 * 0.01).to_bits(),
                "bucket {k}"
            );
            let hi = (first..=last).map(value).fold(f64::NEG_INFINITY, f64::max);
            let lo = (first..=last).map(value).fold(f64::INFINITY, f64::min);
            assert_eq!(b.max[0].to_bits(), hi.to_bits(), "bucket {k}");
            assert_eq!(b.min[0].to_bits(), lo.to_bits(), "bucket {k}");
            assert_eq!(b.min[1].to_bits(), (-hi).to_bits(), "bucket {k}");
        }
    }

    #[test]
    fn a_short_recording_keeps_one_sample_per_bucket() {
        let mut d = Decimator::new(16);
        for i in 0..10 {
            d.push(f64::from(i), &[f64::from(i)]);
        }
        let o = d.finish();
        assert_eq!(o.samples_per_bucket(), 1);
        assert_eq!(o.buckets().len(), 10);
    }
}
