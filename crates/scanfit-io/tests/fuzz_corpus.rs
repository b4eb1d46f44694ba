//! Replays the fuzzing corpora on stable: every file under `fuzz/corpus/*`
//! (the seeds) and `fuzz/regressions/*` (every input a campaign found to
//! crash, hang or allocate without bound, fixed since) is fed to the reader
//! of its target, which must return (Ok or a clean Err) without a panic and
//! within a time bound. A panic fails the test; an allocation beyond memory
//! would abort it.
#![allow(clippy::unwrap_used, clippy::expect_used)]

use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

/// Per-file time bound: every input is small (a few kilobytes).
const BOUND: Duration = Duration::from_secs(5);

fn fuzz_dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../../fuzz")
}

/// Feeds `data` to the target named `target`; returns whether it was
/// accepted (a disagreement between two readers fails the test).
fn feed(target: &str, data: &[u8]) -> bool {
    let compared = |r: Result<bool, scanfit_io::fuzz::Disagreement>| {
        r.unwrap_or_else(|e| panic!("{target}: {e}"))
    };
    match target {
        "ply" => compared(scanfit_io::fuzz::point_file("f.ply", data)),
        "pcd" => compared(scanfit_io::fuzz::point_file("f.pcd", data)),
        "las" => compared(scanfit_io::fuzz::point_file("f.las", data)),
        "laz" => compared(scanfit_io::fuzz::point_file("f.laz", data)),
        "las_stream" => compared(scanfit_io::fuzz::streamed_las_file(data)),
        "text" => compared(scanfit_io::fuzz::point_file("f.xyz", data)),
        "stl" => compared(scanfit_io::fuzz::point_file("f.stl", data)),
        "obj" => compared(scanfit_io::fuzz::point_file("f.obj", data)),
        "curve_json" => scanfit_io::fuzz::curve_document(data),
        "surface_json" => scanfit_io::fuzz::surface_document(data),
        "model_json" => scanfit_io::fuzz::model_document(data),
        other => panic!("unknown fuzz target directory '{other}'"),
    }
}

/// Replays every file of `fuzz/KIND/*/`; returns (files, accepted) per target.
fn replay(kind: &str) -> Vec<(String, usize, usize)> {
    let mut out = Vec::new();
    let mut dirs: Vec<PathBuf> = std::fs::read_dir(fuzz_dir().join(kind))
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.is_dir())
        .collect();
    dirs.sort();
    for dir in dirs {
        let target = dir.file_name().unwrap().to_string_lossy().into_owned();
        let mut files: Vec<PathBuf> = std::fs::read_dir(&dir)
            .unwrap()
            .map(|e| e.unwrap().path())
            .filter(|p| p.is_file() && p.file_name().is_none_or(|n| n != ".gitkeep"))
            .collect();
        files.sort();
        let mut accepted = 0;
        for f in &files {
            let data = std::fs::read(f).unwrap();
            let start = Instant::now();
            accepted += usize::from(feed(&target, &data));
            let took = start.elapsed();
            assert!(took < BOUND, "{}: {took:?}", f.display());
        }
        out.push((target, files.len(), accepted));
    }
    out
}

#[test]
fn seed_corpora_replay_and_the_intact_seeds_are_accepted() {
    let r = replay("corpus");
    let names: Vec<&str> = r.iter().map(|(t, _, _)| t.as_str()).collect();
    assert_eq!(
        names,
        [
            "curve_json",
            "las",
            "las_stream",
            "laz",
            "model_json",
            "obj",
            "pcd",
            "ply",
            "stl",
            "surface_json",
            "text"
        ]
    );
    for (target, files, accepted) in &r {
        assert!(*files > 0, "{target}: no seeds");
        // the seeds are valid files, except the text seed with an empty
        // field, accepted only under the drop policy (point_file tries both)
        assert_eq!(
            accepted, files,
            "{target}: {accepted} of {files} seeds accepted"
        );
    }
}

#[test]
fn regression_inputs_replay_without_a_panic() {
    let r = replay("regressions");
    let total: usize = r.iter().map(|(_, n, _)| n).sum();
    eprintln!("replayed {total} regression inputs: {r:?}");
}

/// The direct binary PLY reader against the general one on mutants of the
/// binary PLY seeds (a fixed-seed stand-in for a campaign on stable): bytes
/// overwritten, header digits changed, files cut short. `point_file` returns
/// an error where the two readers disagree.
#[test]
fn mutated_binary_ply_seeds_read_alike_directly_and_in_general(
) -> Result<(), Box<dyn std::error::Error>> {
    let mut state = 0x2545_f491_4f6c_dd1du64;
    let mut next = |m: usize| {
        state ^= state << 13;
        state ^= state >> 7;
        state ^= state << 17;
        (state % m as u64) as usize
    };
    let (mut mutants, mut accepted) = (0, 0);
    for seed in ["sample_binary_le.ply", "sample_binary_be.ply"] {
        let bytes = std::fs::read(fuzz_dir().join("corpus/ply").join(seed)).expect("seed");
        let head = bytes
            .windows(11)
            .position(|w| w == b"end_header\n")
            .expect("header")
            + 11;
        for _ in 0..1500 {
            let mut m = bytes.clone();
            match next(4) {
                // a byte of the header (counts, types, names)
                0 => m[next(head)] = b"0123456789 \nxyzfloatdouble"[next(26)],
                // bytes of the records
                1 => {
                    for _ in 0..1 + next(8) {
                        let i = head + next(m.len() - head);
                        m[i] = next(256) as u8;
                    }
                }
                // cut short or grown
                2 => m.truncate(next(m.len())),
                _ => m.extend(std::iter::repeat_n(0u8, 1 + next(64))),
            }
            mutants += 1;
            accepted += usize::from(scanfit_io::fuzz::point_file("f.ply", &m)?);
        }
    }
    // the mutants reach both outcomes (so both readers' paths ran)
    assert!(
        accepted > 100 && accepted < mutants,
        "{accepted} of {mutants}"
    );
    Ok(())
}
