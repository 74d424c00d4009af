//! Reading a recording on two threads (one reads, hashes and visits; one parses) behaves as
//! one thread would: every row in order, an error after the rows before it, a visitor's error
//! stops the reading, the hash of every byte; on recordings longer than the blocks in flight.

use calib_run::RunError;
use calib_run::recording::{
    BLOCK_ROWS, BLOCKS_IN_FLIGHT, CHUNK_BYTES, CHUNKS_IN_FLIGHT, RecordingOptions,
    RecordingSummary, Row, read_rows, sha256_hex,
};

/// `read_rows` on a recording with outputs `a` and `b`, no angles, default options.
fn read(
    rec: &[u8],
    visit: impl FnMut(&Row<'_>) -> Result<(), RunError>,
) -> Result<RecordingSummary, RunError> {
    read_rows(
        rec,
        "log.csv",
        &["a", "b"],
        &[],
        &RecordingOptions::default(),
        visit,
    )
}

/// Rows more than the blocks and the chunks in flight hold (so both channels fill).
fn rows() -> usize {
    let by_blocks = 3 * BLOCK_ROWS * BLOCKS_IN_FLIGHT;
    // a row below is about 40 bytes
    let by_bytes = 3 * CHUNK_BYTES * CHUNKS_IN_FLIGHT / 30;
    by_blocks.max(by_bytes)
}

/// A recording of `n` rows, time step 0.01 s, two outputs, with row `bad` (0-based) holding
/// `abc` in output `b`.
fn recording(n: usize, bad: Option<usize>) -> Vec<u8> {
    let mut s = String::from("t_s,a,b\n");
    for i in 0..n {
        let b = if Some(i) == bad {
            "abc".to_string()
        } else {
            format!("{}", -(i as f64) * 0.25)
        };
        s.push_str(&format!("{},{},{b}\n", i as f64 * 0.01, i as f64 * 1.5));
    }
    s.into_bytes()
}

#[test]
fn every_row_reaches_the_visitor_in_order_with_its_values_and_the_hash_of_every_byte() {
    let n = rows();
    let rec = recording(n, None);
    let mut seen = 0usize;
    let summary = read(&rec, |r| {
        assert_eq!(r.index, seen as u64, "rows in order");
        assert_eq!(r.line, seen as u64 + 2, "line of row {seen}");
        // the values are the file's text parsed exactly: equal as bits
        assert_eq!(r.values[0].to_bits(), (seen as f64 * 1.5).to_bits());
        assert_eq!(r.values[1].to_bits(), (-(seen as f64) * 0.25).to_bits());
        assert!(r.angles_deg.is_none());
        seen += 1;
        Ok(())
    })
    .expect("read");
    assert_eq!(seen, n);
    assert_eq!(summary.samples, n as u64);
    assert_eq!(summary.sha256, sha256_hex(&rec));
}

#[test]
fn a_bad_cell_late_in_a_long_recording_is_returned_after_every_row_before_it() {
    let n = rows();
    let bad = n - 7;
    let rec = recording(n, Some(bad));
    let mut seen = 0usize;
    let e = read(&rec, |_| {
        seen += 1;
        Ok(())
    })
    .expect_err("rejected");
    assert_eq!(seen, bad, "the rows before the bad one, no more");
    let msg = e.to_string();
    assert!(
        msg.contains(&format!("log.csv:{} (column `b`)", bad + 2))
            && msg.contains("`abc` is not a number"),
        "{msg}"
    );
}

#[test]
fn a_visitor_error_stops_the_reading_and_is_the_error_returned() {
    let n = rows();
    // a bad cell after the visitor's error: the visitor's error wins, as on one thread
    let rec = recording(n, Some(n - 1));
    let stop = BLOCK_ROWS * 2 + 5;
    let mut seen = 0usize;
    let e = read(&rec, |r| {
        seen += 1;
        if r.index == stop as u64 {
            return Err(RunError::Segments {
                reason: "stop here".into(),
            });
        }
        Ok(())
    })
    .expect_err("stopped");
    assert_eq!(seen, stop + 1, "no row after the failing one is visited");
    assert!(e.to_string().contains("stop here"), "{e}");
}

/// A reader that fails after `left` bytes.
struct FailsAfter<'a> {
    bytes: &'a [u8],
    left: usize,
}

impl std::io::Read for FailsAfter<'_> {
    fn read(&mut self, buf: &mut [u8]) -> std::io::Result<usize> {
        if self.left == 0 {
            return Err(std::io::Error::other("disk gone"));
        }
        let n = buf.len().min(self.left).min(self.bytes.len());
        buf[..n].copy_from_slice(&self.bytes[..n]);
        self.bytes = &self.bytes[n..];
        self.left -= n;
        Ok(n)
    }
}

#[test]
fn a_read_failure_midway_is_a_cannot_read_error_after_the_rows_read_before_it() {
    let n = rows();
    let rec = recording(n, None);
    let half = rec.len() / 2;
    let mut seen = 0usize;
    let e = read_rows(
        FailsAfter {
            bytes: &rec,
            left: half,
        },
        "log.csv",
        &["a", "b"],
        &[],
        &RecordingOptions::default(),
        |_| {
            seen += 1;
            Ok(())
        },
    )
    .expect_err("failed");
    assert!(e.to_string().contains("cannot read: disk gone"), "{e}");
    // the whole rows in the first half were visited, none after it
    let whole_rows = rec[..half].iter().filter(|&&b| b == b'\n').count() - 1;
    assert!(
        seen + 1 >= whole_rows && seen <= whole_rows,
        "{seen} rows visited, {whole_rows} whole rows read"
    );
}

/// Spaces and tabs around the headers and the cells are not part of them (the reader trims
/// each cell itself rather than have the csv crate copy every row into a trimmed one): the
/// same values, bit for bit, as without them.
#[test]
fn blanks_around_headers_and_cells_give_the_same_rows() {
    let plain = recording(50, None);
    let padded = String::from_utf8(plain.clone())
        .unwrap()
        .replace(',', " ,\t ")
        .replace('\n', " \n");
    let collect = |rec: &[u8]| {
        let mut rows = Vec::new();
        read(rec, |r| {
            rows.push((
                r.t_s.to_bits(),
                r.values[0].to_bits(),
                r.values[1].to_bits(),
            ));
            Ok(())
        })
        .expect("read");
        rows
    };
    assert_eq!(collect(&plain), collect(padded.as_bytes()));
}
