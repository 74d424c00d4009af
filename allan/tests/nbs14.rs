//! The deviations against the published reference values of the NBS14 data sets.
//!
//! Source: W. J. Riley, *Handbook of Frequency Stability Analysis*, NIST Special Publication
//! 1065 (2008), section 12.3 (NBS Monograph 140, Annex 8.E test data): the 9-point set
//! (frequency data 892, 809, 823, 798, 671, 644, 883, 903, 677, tau0 = 1 s) with its
//! deviations at tau = 1 and 2, and the 1000-point set from the linear congruential generator
//! n(i+1) = 16807 n(i) mod 2147483647, n(0) = 1234567890 (normalized by 2147483647) with its
//! deviations at tau = 1, 10 and 100 (Table III of Riley's "Handbook" web edition; the same
//! values are in allantools' tests/nbs14, github.com/aewallin/allantools). The values are
//! printed to 7 significant digits: they are compared to half a unit of the last printed
//! digit (relative, at most 1e-6 relative for the 9-point set).

use allan::{Settings, Taus};

/// Half a unit of the 7th significant digit, relative (the printed precision).
const PRINTED: f64 = 0.5e-6;

fn close(got: f64, want: f64, what: &str) {
    let rel = (got - want).abs() / want.abs();
    assert!(
        rel <= PRINTED * 1.000_001,
        "{what}: {got} vs {want} (relative {rel:.2e})"
    );
}

const NBS14_9: [f64; 9] = [
    892.0, 809.0, 823.0, 798.0, 671.0, 644.0, 883.0, 903.0, 677.0,
];

fn nbs14_1000() -> Vec<f64> {
    let mut n = vec![1_234_567_890u64];
    for i in 0..999 {
        n.push(16807 * n[i] % 2_147_483_647);
    }
    assert_eq!(&n[1..4], &[395_529_916, 1_209_410_747, 633_705_974]);
    n.iter().map(|&v| v as f64 / 2_147_483_647.0).collect()
}

fn points(data: &[f64], taus: &[f64], overlap: u64) -> Vec<allan::AllanPoint> {
    let settings = Settings::new(1.0)
        .overlap(overlap)
        .taus(Taus::List(taus.to_vec()));
    allan::analyse(data, settings).unwrap().points().to_vec()
}

/// NBS14 9-point set, tau = 1 and 2 s: ADEV (not overlapping), OADEV, MDEV, overlapping HDEV,
/// HDEV (not overlapping) and TOTDEV, to the printed digits (SP 1065 p. 107).
#[test]
fn nbs14_nine_point_deviations_match_sp1065() {
    let o = points(&NBS14_9, &[1.0, 2.0], 256);
    let n = points(&NBS14_9, &[1.0, 2.0], 1);
    for (i, (adev, oadev, mdev, ohdev, hdev, totdev)) in [
        (91.22945, 91.22945, 91.22945, 70.80607, 70.80607, 91.22945),
        (115.8082, 85.95287, 74.78849, 85.61487, 116.7980, 93.90379),
    ]
    .into_iter()
    .enumerate()
    {
        close(n[i].adev(), adev, "ADEV");
        close(o[i].adev(), oadev, "OADEV");
        close(o[i].mdev(), mdev, "MDEV");
        close(o[i].hdev(), ohdev, "overlapping HDEV");
        close(n[i].hdev(), hdev, "HDEV");
        close(o[i].totdev(), totdev, "TOTDEV");
    }
}

/// NBS14 1000-point set, tau = 1, 10, 100 s: ADEV, OADEV, MDEV, HDEV, overlapping HDEV and
/// TOTDEV (SP 1065's "doubly reflected" values, without bias correction) to the printed digits
/// (SP 1065 p. 108).
#[test]
fn nbs14_thousand_point_deviations_match_sp1065() {
    let data = nbs14_1000();
    let taus = [1.0, 10.0, 100.0];
    let o = points(&data, &taus, 256);
    let n = points(&data, &taus, 1);
    let adev = [2.922319e-01, 9.965736e-02, 3.897804e-02];
    let oadev = [2.922319e-01, 9.159953e-02, 3.241343e-02];
    let mdev = [2.922319e-01, 6.172376e-02, 2.170921e-02];
    let hdev = [2.943883e-01, 1.052754e-01, 3.910860e-02];
    let ohdev = [2.943883e-01, 9.581083e-02, 3.237638e-02];
    let totdev = [2.922319e-01, 9.134743e-02, 3.406530e-02];
    for i in 0..3 {
        close(n[i].adev(), adev[i], "ADEV");
        close(o[i].adev(), oadev[i], "OADEV");
        close(o[i].mdev(), mdev[i], "MDEV");
        close(n[i].hdev(), hdev[i], "HDEV");
        close(o[i].hdev(), ohdev[i], "overlapping HDEV");
        close(o[i].totdev(), totdev[i], "TOTDEV");
    }
}
