//! A request to stop (SIGINT or SIGTERM, set by the programs' signal
//! handlers): renders check it between rows and passes, so a progressive
//! render can keep the passes it has finished and exit cleanly.
//!
//! Before a program calls [`keep_work`] (while it reads its inputs and
//! loads the scene) there is nothing to keep, and its handler exits at the
//! first signal: the loader does not have to look for the request, and a
//! read that blocks is not waited for.

use std::sync::atomic::{AtomicBool, Ordering};

static REQUESTED: AtomicBool = AtomicBool::new(false);
static KEEPING: AtomicBool = AtomicBool::new(false);

/// Asks every render in this process to stop as soon as it can.
pub fn request() {
    REQUESTED.store(true, Ordering::Relaxed);
}

/// Whether a stop was asked for.
pub fn requested() -> bool {
    REQUESTED.load(Ordering::Relaxed)
}

/// From now on the work done is worth keeping: a stop request is answered
/// by the work itself (its passes written), not by exiting at once.
pub fn keep_work() {
    KEEPING.store(true, Ordering::Relaxed);
}

/// Whether [`keep_work`] was called: if not, a signal may exit at once.
pub fn work_to_keep() -> bool {
    KEEPING.load(Ordering::Relaxed)
}

/// What a signal does in `photonmap` (its handler calls this): before
/// rendering starts there is nothing to keep, and the first exits at once;
/// during a render the first asks it to stop (a progressive render writes
/// the passes it has and exits 130), a second exits at once. An exit
/// removes any file half-written.
pub fn on_signal() {
    if !work_to_keep() {
        crate::output::remove_temporaries();
        eprintln!("\nphotonmap: interrupted (no half-written file is left)");
        std::process::exit(130);
    }
    if requested() {
        crate::output::remove_temporaries();
        std::process::exit(130);
    }
    eprintln!("\nphotonmap: stopping (the passes finished are kept; Ctrl-C again to quit at once)");
    request();
}
