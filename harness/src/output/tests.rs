//! The output set's own tests: the folder lock, links.

use super::*;

/// Threads started together on a folder with a stale lock file (a dead run's process id):
/// exactly one holds the lock at a time. The process-id lock this replaced let two take over
/// the stale lock together (each removed the other's), or failed on the removed file.
#[test]
fn one_lock_owner_among_racing_takers() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path();
    for round in 0..40 {
        std::fs::write(dir.join(LOCK), b"999999999").unwrap();
        let threads = 6;
        let barrier = std::sync::Barrier::new(threads);
        let held = std::sync::atomic::AtomicUsize::new(0);
        let most = std::sync::atomic::AtomicUsize::new(0);
        let errors = Mutex::new(Vec::new());
        std::thread::scope(|s| {
            for _ in 0..threads {
                s.spawn(|| {
                    use std::sync::atomic::Ordering::SeqCst;
                    barrier.wait();
                    match FolderLock::take(dir) {
                        Ok(lock) => {
                            let now = held.fetch_add(1, SeqCst) + 1;
                            most.fetch_max(now, SeqCst);
                            std::thread::sleep(std::time::Duration::from_millis(2));
                            held.fetch_sub(1, SeqCst);
                            lock.release();
                        }
                        Err(LockError::InUse(_)) => {}
                        Err(e) => errors.lock().unwrap().push(format!("{e:?}")),
                    }
                });
            }
        });
        let errors = errors.into_inner().unwrap();
        assert!(errors.is_empty(), "round {round}: {errors:?}");
        assert_eq!(
            most.load(std::sync::atomic::Ordering::SeqCst),
            1,
            "round {round}: two held the lock at once"
        );
    }
}

/// Threads taking and releasing the lock over and over: a release removes the lock file,
/// so a taker that opened the file just before may lock the removed file while another
/// creates and locks a new one. Exactly one may hold it at any time (the check that the
/// locked file is still the one at the path; without it two held it at once here).
#[test]
fn a_released_lock_file_is_never_held_twice() {
    use std::sync::atomic::{AtomicUsize, Ordering::SeqCst};
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path();
    let (held, most, taken) = (
        AtomicUsize::new(0),
        AtomicUsize::new(0),
        AtomicUsize::new(0),
    );
    let errors = Mutex::new(Vec::new());
    let deadline = std::time::Instant::now() + std::time::Duration::from_millis(1500);
    std::thread::scope(|s| {
        for _ in 0..6 {
            s.spawn(|| {
                while std::time::Instant::now() < deadline {
                    match FolderLock::take(dir) {
                        Ok(lock) => {
                            let now = held.fetch_add(1, SeqCst) + 1;
                            most.fetch_max(now, SeqCst);
                            taken.fetch_add(1, SeqCst);
                            std::thread::yield_now();
                            held.fetch_sub(1, SeqCst);
                            lock.release();
                        }
                        Err(LockError::InUse(_)) => std::thread::yield_now(),
                        Err(e) => errors.lock().unwrap().push(format!("{e:?}")),
                    }
                }
            });
        }
    });
    let errors = errors.into_inner().unwrap();
    assert!(errors.is_empty(), "{:?}", &errors[..errors.len().min(3)]);
    assert!(taken.load(SeqCst) > 0);
    assert_eq!(most.load(SeqCst), 1, "two held the lock at once");
}

/// A replaced subfolder that is a symbolic link to a folder outside: publication removes
/// nothing there (before, every file in the link's target was deleted).
#[cfg(unix)]
#[test]
fn nothing_is_removed_through_a_link() {
    let tmp = tempfile::tempdir().unwrap();
    let (out, outside) = (tmp.path().join("out"), tmp.path().join("outside"));
    std::fs::create_dir_all(&out).unwrap();
    std::fs::create_dir_all(&outside).unwrap();
    std::fs::write(outside.join("precious.txt"), b"mine").unwrap();
    // Declared while the link is absent, made a link before publication (another process
    // could do this mid-run): the declaration check cannot see it, publication must.
    let set = OutputSet::begin("out", &out).unwrap();
    set.replace(Path::new("tiles")).unwrap();
    std::os::unix::fs::symlink(&outside, out.join("tiles")).unwrap();
    let e = set.publish().unwrap_err().to_string();
    assert!(e.contains("symbolic link"), "{e}");
    assert!(outside.join("precious.txt").exists());
    // With the link present before the command: refused when the set opens, naming it.
    let e = OutputSet::begin("out", &out).err().unwrap().to_string();
    assert!(e.contains("'out'") && e.contains("tiles"), "{e}");
    // And a write below the link is refused rather than made outside.
    std::fs::remove_file(out.join("tiles")).unwrap();
    let set = OutputSet::begin("out", &out).unwrap();
    std::os::unix::fs::symlink(&outside, out.join("tiles")).unwrap();
    let e = write_atomic(&out.join("tiles/new.txt"), b"x")
        .unwrap_err()
        .to_string();
    assert!(e.contains("symbolic link"), "{e}");
    assert!(!outside.join("new.txt").exists());
    drop(set);
    assert!(outside.join("precious.txt").exists());
}
