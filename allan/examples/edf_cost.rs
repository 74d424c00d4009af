//! Scratch: EDF of decimated vs fully overlapping.
use allan::{PowerLaw, edf::edf};
fn main() {
    for &n in &[1u64 << 20, 1u64 << 27] {
        for &m in &[512u64, 4096, 1 << 14, 1 << 17] {
            if 3 * m > n {
                continue;
            }
            for p in PowerLaw::ALL {
                let full = edf(p, n, m, 1);
                let mut line = format!("N=2^{} m={m} {p:>12}: full {full:.4}", n.trailing_zeros());
                for r in [16u64, 64, 256, 1024] {
                    let d = edf(p, n, m, (m / r).max(1));
                    line += &format!("  R={r}: {:.6}", d / full);
                }
                println!("{line}");
            }
        }
    }
}
