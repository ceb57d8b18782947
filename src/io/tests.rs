use super::*;

fn names(dir: &Path) -> Vec<String> {
    let mut v: Vec<String> =
        std::fs::read_dir(dir).unwrap().map(|e| e.unwrap().file_name().into_string().unwrap()).collect();
    v.sort();
    v
}

#[test]
fn a_commit_places_every_file_and_replaces_old_ones() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    std::fs::write(d.join("a"), b"old").unwrap();
    let mut set = OutputSet::new();
    set.add(&d.join("a"), b"new").unwrap();
    set.add(&d.join("sub/deeper/b"), b"bee").unwrap();
    set.add_executable(&d.join("run.sh"), b"#!/bin/sh\n").unwrap();
    // Staged, not placed: the old file is still there, the new ones are not.
    assert_eq!(std::fs::read(d.join("a")).unwrap(), b"old");
    assert!(!d.join("sub/deeper/b").exists() && !d.join("run.sh").exists());
    assert_eq!(set.len(), 3);
    set.commit().unwrap();
    assert_eq!(std::fs::read(d.join("a")).unwrap(), b"new");
    assert_eq!(std::fs::read(d.join("sub/deeper/b")).unwrap(), b"bee");
    // No temporary file and no kept old file is left.
    assert_eq!(names(d), ["a", "run.sh", "sub"]);
    assert_eq!(names(&d.join("sub/deeper")), ["b"]);
    #[cfg(unix)]
    {
        use std::os::unix::fs::PermissionsExt;
        let mode = |p: &str| std::fs::metadata(d.join(p)).unwrap().permissions().mode() & 0o777;
        assert_eq!((mode("a"), mode("run.sh")), (0o644, 0o755));
    }
}

#[test]
fn a_set_dropped_before_its_commit_leaves_nothing() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    std::fs::write(d.join("a"), b"old").unwrap();
    {
        let mut set = OutputSet::new();
        set.add(&d.join("x/y/one"), b"1").unwrap();
        set.add(&d.join("a"), b"new").unwrap();
        set.add(&d.join("two"), b"2").unwrap();
    }
    // The folders it created went with its files; the old file is untouched.
    assert_eq!(names(d), ["a"]);
    assert_eq!(std::fs::read(d.join("a")).unwrap(), b"old");
}

#[test]
fn a_file_that_cannot_be_staged_fails_the_set_naming_its_target() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    std::fs::write(d.join("F"), b"a file").unwrap();
    std::fs::create_dir(d.join("folder")).unwrap();
    let mut set = OutputSet::new();
    set.add(&d.join("new/one"), b"1").unwrap();
    let e = set.add(&d.join("F/two"), b"2").unwrap_err();
    assert_eq!(e.subject, d.join("F/two").display().to_string());
    assert!(e.message.contains("is a file, not a folder"), "{e}");
    let e = set.add(&d.join("folder"), b"3").unwrap_err();
    assert!(e.message.contains("it is a folder"), "{e}");
    drop(set);
    assert_eq!(names(d), ["F", "folder"]);
}

#[test]
fn a_rename_failing_midway_puts_back_what_the_set_replaced() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    std::fs::write(d.join("kept"), b"old").unwrap();
    let mut set = OutputSet::new();
    set.add(&d.join("fresh"), b"new file").unwrap();
    set.add(&d.join("kept"), b"replaced").unwrap();
    set.add(&d.join("sub/inner"), b"in a new folder").unwrap();
    set.add(&d.join("last"), b"never placed").unwrap();
    // The last target turns into a folder after staging: its rename fails after three
    // renames succeeded.
    std::fs::create_dir_all(d.join("last/occupied")).unwrap();
    let e = set.commit().unwrap_err();
    assert_eq!(e.subject, d.join("last").display().to_string());
    assert!(!e.to_string().contains(TEMP_PREFIX), "{e}");
    assert_eq!(std::fs::read(d.join("kept")).unwrap(), b"old");
    assert_eq!(names(d), ["kept", "last"]);
    assert_eq!(names(&d.join("last")), ["occupied"]);
}

#[test]
fn one_file_named_twice_is_refused() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    std::fs::create_dir(d.join("sub")).unwrap();
    let mut set = OutputSet::new();
    set.add(&d.join("a"), b"1").unwrap();
    let e = set.add(&d.join("sub/../a"), b"2").unwrap_err();
    assert!(e.message.contains("named twice"), "{e}");
}

#[test]
fn checks_refuse_paths_that_can_never_be_written() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    std::fs::write(d.join("F"), b"a file").unwrap();
    assert!(check_writable(&d.join("new/deeper/file")).is_ok());
    assert!(check_writable(&d.join("F")).is_ok(), "an existing file is replaced");
    assert!(check_writable(d).unwrap_err().message.contains("is a folder"));
    let e = check_writable(&d.join("F/x/y")).unwrap_err();
    assert_eq!(e.message, format!("cannot write: {} is a file, not a folder", d.join("F").display()));
    assert!(check_folder(&d.join("new/out")).is_ok());
    assert!(check_folder(d).is_ok());
    assert_eq!(check_folder(&d.join("F")).unwrap_err().message, "is a file, not a folder");
    assert!(check_folder(&d.join("F/out")).unwrap_err().message.contains("cannot create the folder"));
    // Relative paths: the working folder exists.
    assert!(check_writable(Path::new("no-such-file-here")).is_ok());
}
