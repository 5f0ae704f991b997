//! Page replacement simulated directly, one memory size at a time, to check the paging model
//! (`nakamaru-3.2`): [`Lru`] is what Mattson's stack algorithm ([`super::paging::Mattson`])
//! assumes, so the two must count the same faults on the same stream; [`Clock`] (second chance)
//! is the approximation of LRU a kernel actually runs, so its difference from LRU says what the
//! model's LRU assumption costs.

/// Exact LRU over `frames` page frames: a doubly linked recency list over page numbers.
pub struct Lru {
    frames: usize,
    prev: Vec<u32>,
    next: Vec<u32>,
    resident: Vec<bool>,
    head: u32,
    tail: u32,
    len: usize,
    pub faults: u64,
}

const NIL: u32 = u32::MAX;

impl Lru {
    /// For pages numbered below `pages`.
    pub fn new(pages: u64, frames: u64) -> Lru {
        let n = pages as usize;
        Lru {
            frames: frames.max(1) as usize,
            prev: vec![NIL; n],
            next: vec![NIL; n],
            resident: vec![false; n],
            head: NIL,
            tail: NIL,
            len: 0,
            faults: 0,
        }
    }

    fn unlink(&mut self, p: u32) {
        let (a, b) = (self.prev[p as usize], self.next[p as usize]);
        if a != NIL {
            self.next[a as usize] = b;
        } else {
            self.head = b;
        }
        if b != NIL {
            self.prev[b as usize] = a;
        } else {
            self.tail = a;
        }
    }

    fn push_front(&mut self, p: u32) {
        self.prev[p as usize] = NIL;
        self.next[p as usize] = self.head;
        if self.head != NIL {
            self.prev[self.head as usize] = p;
        }
        self.head = p;
        if self.tail == NIL {
            self.tail = p;
        }
    }

    pub fn access(&mut self, page: u64) {
        let p = page as u32;
        if self.resident[p as usize] {
            if self.head != p {
                self.unlink(p);
                self.push_front(p);
            }
            return;
        }
        self.faults += 1;
        if self.len == self.frames {
            let victim = self.tail;
            self.unlink(victim);
            self.resident[victim as usize] = false;
        } else {
            self.len += 1;
        }
        self.resident[p as usize] = true;
        self.push_front(p);
    }
}

/// CLOCK (second chance) over `frames` frames: a hit sets the page's reference bit; a fault
/// sweeps the hand, clearing bits, to the first frame whose bit is clear.
pub struct Clock {
    frame_page: Vec<u32>,
    referenced: Vec<bool>,
    slot: Vec<u32>,
    hand: usize,
    used: usize,
    pub faults: u64,
}

impl Clock {
    pub fn new(pages: u64, frames: u64) -> Clock {
        let f = frames.max(1) as usize;
        Clock {
            frame_page: vec![NIL; f],
            referenced: vec![false; f],
            slot: vec![NIL; pages as usize],
            hand: 0,
            used: 0,
            faults: 0,
        }
    }

    pub fn access(&mut self, page: u64) {
        let s = self.slot[page as usize];
        if s != NIL {
            self.referenced[s as usize] = true;
            return;
        }
        self.faults += 1;
        let f = if self.used < self.frame_page.len() {
            self.used += 1;
            self.used - 1
        } else {
            while self.referenced[self.hand] {
                self.referenced[self.hand] = false;
                self.hand = (self.hand + 1) % self.frame_page.len();
            }
            let f = self.hand;
            self.slot[self.frame_page[f] as usize] = NIL;
            self.hand = (self.hand + 1) % self.frame_page.len();
            f
        };
        self.frame_page[f] = page as u32;
        self.referenced[f] = true;
        self.slot[page as usize] = f as u32;
    }
}

#[cfg(test)]
mod tests {
    use super::super::paging::Mattson;
    use super::*;

    #[test]
    fn direct_lru_counts_what_mattson_counts_and_clock_differs_by_little() {
        let mut x = 99u64;
        let stream: Vec<u64> = (0..50_000)
            .map(|i| {
                x = x
                    .wrapping_mul(6364136223846793005)
                    .wrapping_add(1442695040888963407);
                if i % 4 == 0 {
                    (x >> 33) % 30
                } else {
                    (x >> 33) % 700
                }
            })
            .collect();
        let mut m = Mattson::new(700);
        for &p in &stream {
            m.access(p);
        }
        for frames in [1, 10, 64, 300, 699, 700] {
            let mut lru = Lru::new(700, frames);
            let mut clock = Clock::new(700, frames);
            for &p in &stream {
                lru.access(p);
                clock.access(p);
            }
            assert_eq!(lru.faults, m.faults(frames), "{frames}");
            assert!(clock.faults >= m.cold());
            let d = clock.faults as f64 / lru.faults as f64;
            assert!(
                (0.8..1.25).contains(&d),
                "{frames}: clock {} lru {}",
                clock.faults,
                lru.faults
            );
        }
    }
}
