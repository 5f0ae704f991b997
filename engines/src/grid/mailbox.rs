//! Mailboxes (Arnaldi, Priol and Bouatouch 1987; seed 000 §1.1): a primitive registered in
//! several cells is tested once per ray, not once per cell.
//!
//! Rayshade keeps the last ray number in each object, which is shared mutable state: two threads
//! tracing at once would overwrite each other's stamps. Here the stamps belong to the caller's
//! batch instead. A [`Mailbox`] is one array of `u32` stamps, one per primitive, plus the number
//! of the ray being traced; each `intersect`/`occluded` call takes one from the engine's
//! [`MailboxPool`] for the whole batch and gives it back at the end, so a mailbox is only ever
//! used by one thread at a time and is allocated once per thread, not once per call. The pool's
//! lock is taken twice per batch (thousands of rays), never per ray.

use std::sync::Mutex;

/// Stamps of one batch: `stamps[p] == ray` when primitive p was tested against the current ray.
pub struct Mailbox {
    pub(super) stamps: Vec<u32>,
    pub(super) ray: u32,
}

impl Mailbox {
    fn new(prims: usize) -> Mailbox {
        Mailbox {
            stamps: vec![0; prims],
            ray: 0,
        }
    }

    /// Starts a new ray: every stamp becomes stale at once.
    #[inline]
    pub fn next_ray(&mut self) {
        self.ray = self.ray.wrapping_add(1);
        if self.ray == 0 {
            // After 2^32 − 1 rays the numbers come round: clear so no old stamp matches.
            self.stamps.fill(0);
            self.ray = 1;
        }
    }

    /// Whether primitive `p` was already tested against the current ray.
    #[inline]
    pub fn tested(&self, p: u32) -> bool {
        self.stamps[p as usize] == self.ray
    }

    /// Records that primitive `p` has been tested against the current ray.
    #[inline]
    pub fn mark(&mut self, p: u32) {
        self.stamps[p as usize] = self.ray;
    }
}

/// Mailboxes not in use, for the calls to come.
pub struct MailboxPool {
    prims: usize,
    free: Mutex<Vec<Mailbox>>,
}

impl MailboxPool {
    pub fn new(prims: usize) -> MailboxPool {
        MailboxPool {
            prims,
            free: Mutex::new(Vec::new()),
        }
    }

    /// A mailbox for one batch: a returned one if any, else a new one.
    pub fn take(&self) -> Mailbox {
        let spare = self.free.lock().ok().and_then(|mut v| v.pop());
        spare.unwrap_or_else(|| Mailbox::new(self.prims))
    }

    /// Gives a mailbox back at the end of a batch.
    pub fn give(&self, m: Mailbox) {
        if let Ok(mut v) = self.free.lock() {
            v.push(m);
        }
    }

    /// Bytes of one mailbox (each thread tracing at once holds one).
    pub fn bytes_each(&self) -> u64 {
        (self.prims * 4) as u64
    }
}
