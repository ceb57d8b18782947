//! Every committed seed of the fuzz targets (fuzz/corpus/<target>/) through the body the
//! fuzzer runs (`fxrt::fuzzing`), so the targets stay compiled and exercised without
//! libFuzzer: no seed may panic, and each target's seeds must reach both outcomes.

use fxrt::fuzzing::{TARGETS, run};
use std::path::PathBuf;

#[test]
fn every_corpus_seed_runs_through_its_target() {
    let corpus = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("fuzz/corpus");
    let scratch = tempfile::tempdir().unwrap();
    for target in TARGETS {
        let mut files: Vec<PathBuf> =
            std::fs::read_dir(corpus.join(target)).unwrap().map(|e| e.unwrap().path()).collect();
        files.sort();
        let (mut ok, mut refused) = (0, 0);
        for f in &files {
            match run(target, &std::fs::read(f).unwrap(), scratch.path()) {
                Ok(()) => ok += 1,
                Err(e) => {
                    assert!(!e.to_string().contains('\n'), "{}: {e}", f.display());
                    refused += 1;
                }
            }
        }
        // The seeds are chosen to cover both: scenes that build and bad input refused.
        assert!(ok > 0 && refused > 0, "{target}: {ok} seeds built, {refused} refused");
    }
}
