//! Kills writer processes at random moments and checks the all-or-nothing
//! property after recovery: the three outputs of a run (in two directories)
//! all hold the previous run's content or all hold the new one, and no
//! temporary, backup or journal is left.
//!
//! The writer is this test binary itself, started with `SCANFIT_KILL_CHILD`
//! set (the `child_writer` test then writes one generation and exits);
//! `SCANFIT_ATOMIC_PAUSE_MS` makes every step of the write take a few
//! milliseconds, so that a kill at a uniformly random time lands in every
//! phase: staging, journal, the hard links and renames, the clean-up.
#![allow(clippy::unwrap_used, clippy::expect_used)]

use std::path::{Path, PathBuf};
use std::time::Duration;

fn targets(root: &Path) -> [PathBuf; 3] {
    [
        root.join("one/a.json"),
        root.join("two/b.ply"),
        root.join("one/c.png"),
    ]
}

/// The content of output `k` of generation `g` (long enough that staging
/// takes a moment).
fn content(g: u32, k: usize) -> Vec<u8> {
    let mut v = format!("generation {g} file {k}\n").into_bytes();
    v.resize(64 * 1024, b'0' + (g % 10) as u8);
    v
}

#[test]
fn child_writer() {
    let Ok(spec) = std::env::var("SCANFIT_KILL_CHILD") else {
        return;
    };
    let (root, g) = spec.split_once('|').unwrap();
    let g: u32 = g.parse().unwrap();
    let files: Vec<(PathBuf, Vec<u8>)> = targets(Path::new(root))
        .into_iter()
        .enumerate()
        .map(|(k, p)| (p, content(g, k)))
        .collect();
    scanfit_io::write_all_atomic(&files).unwrap();
}

/// Which generation every target holds, if they agree.
fn generation(root: &Path) -> Option<u32> {
    let gens: Vec<Option<u32>> = targets(root)
        .iter()
        .enumerate()
        .map(|(k, p)| {
            let bytes = std::fs::read(p).ok()?;
            (0..1000).find(|&g| content(g, k) == bytes)
        })
        .collect();
    let first = gens[0]?;
    gens.iter().all(|g| *g == Some(first)).then_some(first)
}

fn leftovers(root: &Path) -> Vec<String> {
    let mut v = Vec::new();
    for d in ["one", "two"] {
        for e in std::fs::read_dir(root.join(d)).unwrap() {
            let n = e.unwrap().file_name().to_string_lossy().into_owned();
            if n.starts_with('.') {
                v.push(format!("{d}/{n}"));
            }
        }
    }
    v
}

#[test]
fn killed_runs_leave_the_old_set_or_the_new_one() {
    let root = std::env::temp_dir().join(format!("scanfit-kill-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&root);
    std::fs::create_dir_all(root.join("one")).unwrap();
    std::fs::create_dir_all(root.join("two")).unwrap();
    let exe = std::env::current_exe().unwrap();
    let run = |g: u32| {
        std::process::Command::new(&exe)
            .args(["--exact", "child_writer", "--test-threads=1", "-q"])
            .env("SCANFIT_KILL_CHILD", format!("{}|{g}", root.display()))
            .env("SCANFIT_ATOMIC_PAUSE_MS", "15")
            .stdout(std::process::Stdio::null())
            .stderr(std::process::Stdio::null())
            .spawn()
            .unwrap()
    };
    // generation 0, complete
    assert!(run(0).wait().unwrap().success());
    assert_eq!(generation(&root), Some(0));
    let mut current = 0;
    let mut seed = 0x2545_f491_4f6c_dd1du64;
    let (mut old, mut new, mut in_rename) = (0, 0, 0);
    let trials = 40;
    for g in 1..=trials {
        seed ^= seed << 13;
        seed ^= seed >> 7;
        seed ^= seed << 17;
        // the run sleeps 15 ms after each of about 12 steps, plus the
        // start-up of the process: kill anywhere in 0..300 ms
        let delay = Duration::from_millis(seed % 300);
        let mut child = run(g);
        std::thread::sleep(delay);
        let _ = child.kill();
        let _ = child.wait();
        // a journal still saying "Renaming" means the kill landed between
        // the first link/rename and the end of the commit
        for d in ["one", "two"] {
            for e in std::fs::read_dir(root.join(d)).unwrap() {
                let p = e.unwrap().path();
                let name = p.file_name().unwrap().to_string_lossy().into_owned();
                if name.starts_with(".scanfit-journal.")
                    && !name.ends_with(".writing")
                    && std::fs::read_to_string(&p).is_ok_and(|t| t.contains("Renaming"))
                    && d == "one"
                {
                    in_rename += 1;
                }
            }
        }
        // the next run's recovery
        for d in ["one", "two"] {
            scanfit_io::recover(&root.join(d)).unwrap();
        }
        assert_eq!(
            leftovers(&root),
            Vec::<String>::new(),
            "trial {g} after {delay:?}"
        );
        match generation(&root) {
            Some(x) if x == current => old += 1,
            Some(x) if x == g => {
                new += 1;
                current = g;
            }
            other => panic!(
                "trial {g} killed after {delay:?}: the outputs are a mixed set ({other:?}, before {current})"
            ),
        }
    }
    eprintln!("{trials} killed runs: {old} left the old set, {new} the new set; {in_rename} killed while renaming");
    assert_eq!(old + new, trials);
    assert!(old > 0 && new > 0, "old {old}, new {new}");
    assert!(in_rename > 0, "no kill landed in the rename phase");
    // a normal run afterwards completes
    assert!(run(trials + 1).wait().unwrap().success());
    assert_eq!(generation(&root), Some(trials + 1));
    std::fs::remove_dir_all(&root).unwrap();
}
