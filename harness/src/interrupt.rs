//! **Polite stops**: SIGTERM (what Slurm and Kubernetes send before they preempt, evict or
//! requeue a job) and SIGINT (Ctrl-C) turn into [`Error::Interrupted`] at the next point that
//! checks, so a command finishes nothing new, keeps what it completed and says so; a second
//! signal ends the process at once.
//!
//! A command that can stop cleanly calls [`install`] once; the frame loop calls [`check`]
//! before every frame (`run::runner`), and `reproduce all` keeps its completed targets for a
//! resume (docs/fleet.md). Without [`install`] the signals keep their default action.

use std::sync::atomic::{AtomicI32, Ordering};

use crate::{Error, Result};

/// The signal received (0: none).
static RECEIVED: AtomicI32 = AtomicI32::new(0);

/// The exit status of a command stopped by a signal with its completed work kept: 75,
/// `EX_TEMPFAIL` of sysexits.h ("try again later"): the status `deploy/`'s launchers
/// requeue on.
pub const EXIT_STATUS: u8 = 75;

#[cfg(unix)]
extern "C" fn on_signal(signal: libc::c_int) {
    // Async-signal-safe only: an atomic swap, `write` and `_exit`.
    let before = RECEIVED.swap(signal, Ordering::SeqCst);
    if before == libc::SIGTERM && signal == libc::SIGTERM {
        // A scheduler may send SIGTERM twice (to the job and through its launcher): the stop
        // already under way goes on.
        return;
    }
    if before != 0 {
        // SAFETY: `_exit` is async-signal-safe and ends the process without unwinding.
        unsafe { libc::_exit(128 + signal) };
    }
    const SAY: &[u8] =
        b"\ngibench: stopping before the next frame (a second signal stops at once)\n";
    // SAFETY: `write` is async-signal-safe; the buffer is static.
    unsafe { libc::write(2, SAY.as_ptr().cast(), SAY.len()) };
}

/// Turns SIGTERM and SIGINT into [`Error::Interrupted`] at the next [`check`]. Idempotent.
pub fn install() {
    #[cfg(unix)]
    for signal in [libc::SIGTERM, libc::SIGINT] {
        // SAFETY: the handler only touches an atomic and calls `_exit`; `signal` is valid.
        unsafe {
            libc::signal(signal, on_signal as *const () as libc::sighandler_t);
        }
    }
}

/// The name of the signal received, if any.
pub fn received() -> Option<&'static str> {
    match RECEIVED.load(Ordering::SeqCst) {
        0 => None,
        #[cfg(unix)]
        libc::SIGTERM => Some("SIGTERM"),
        #[cfg(unix)]
        libc::SIGINT => Some("SIGINT"),
        _ => Some("a signal"),
    }
}

/// `Err(Error::Interrupted)` once a signal was received; `where_` says what was stopped.
pub fn check(where_: impl FnOnce() -> String) -> Result<()> {
    match received() {
        None => Ok(()),
        Some(signal) => Err(Error::Interrupted {
            signal,
            at: where_(),
        }),
    }
}
