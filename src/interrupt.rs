//! A request to stop (SIGINT or SIGTERM, set by the programs' signal
//! handlers): renders check it between rows and passes, so a progressive
//! render can keep the passes it has finished and exit cleanly.

use std::sync::atomic::{AtomicBool, Ordering};

static REQUESTED: AtomicBool = AtomicBool::new(false);

/// Asks every render in this process to stop as soon as it can.
pub fn request() {
    REQUESTED.store(true, Ordering::Relaxed);
}

/// Whether a stop was asked for.
pub fn requested() -> bool {
    REQUESTED.load(Ordering::Relaxed)
}
