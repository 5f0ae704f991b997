//! Mattson's stack algorithm (Mattson, Gecsei, Slutz and Traiger 1970): one pass over a page
//! stream gives the LRU stack distance of every access, hence the page faults of an LRU memory
//! of every size at once (an access faults in a memory of M pages iff its distance exceeds M).
//!
//! The distance of an access is the number of distinct pages touched since the previous access
//! to the same page, plus one. With a Fenwick tree over access times holding a 1 at each page's
//! latest access, it is a range count: O(log n) per access. Times are renumbered when the tree
//! fills, keeping it at a few times the number of distinct pages.

/// Stack distances of a page stream.
pub struct Mattson {
    /// Latest access time of each page (`u32::MAX`: never).
    last: Vec<u32>,
    tree: Vec<u32>,
    time: u32,
    /// `hist[d - 1]`: accesses at distance d.
    hist: Vec<u64>,
    cold: u64,
    accesses: u64,
    prev: u64,
}

impl Mattson {
    /// For pages numbered below `pages`.
    pub fn new(pages: u64) -> Mattson {
        let n = pages as usize;
        Mattson {
            last: vec![u32::MAX; n],
            tree: vec![0; (4 * n).max(1 << 16) + 1],
            time: 0,
            hist: vec![0; n + 1],
            cold: 0,
            accesses: 0,
            prev: u64::MAX,
        }
    }

    fn add(&mut self, i: u32, v: i32) {
        let mut i = i as usize + 1;
        while i < self.tree.len() {
            self.tree[i] = self.tree[i].wrapping_add_signed(v);
            i += i & i.wrapping_neg();
        }
    }

    /// Marks at times `0..=i`.
    fn prefix(&self, i: u32) -> u32 {
        let mut i = i as usize + 1;
        let mut s = 0;
        while i > 0 {
            s += self.tree[i];
            i &= i - 1;
        }
        s
    }

    /// Renumbers the live marks 0..k in time order.
    fn compact(&mut self) {
        let mut live: Vec<(u32, usize)> = self
            .last
            .iter()
            .enumerate()
            .filter(|(_, &t)| t != u32::MAX)
            .map(|(p, &t)| (t, p))
            .collect();
        live.sort_unstable();
        self.tree.fill(0);
        for (k, &(_, p)) in live.iter().enumerate() {
            self.last[p] = k as u32;
        }
        self.time = 0;
        for _ in 0..live.len() {
            self.add(self.time, 1);
            self.time += 1;
        }
    }

    pub fn access(&mut self, page: u64) {
        self.accesses += 1;
        if page == self.prev {
            // The same page again: distance 1, nothing moves.
            self.hist[0] += 1;
            return;
        }
        self.prev = page;
        if self.time as usize + 1 >= self.tree.len() {
            self.compact();
        }
        let t = self.time;
        let p = page as usize;
        let l = self.last[p];
        if l == u32::MAX {
            self.cold += 1;
        } else {
            let between = self.prefix(t.saturating_sub(1)) - self.prefix(l);
            self.hist[between as usize] += 1;
            self.add(l, -1);
        }
        self.add(t, 1);
        self.last[p] = t;
        self.time += 1;
    }

    /// Faults of an LRU memory of `frames` pages (cold misses included).
    pub fn faults(&self, frames: u64) -> u64 {
        let from = (frames as usize).min(self.hist.len());
        self.cold + self.hist[from..].iter().sum::<u64>()
    }

    pub fn accesses(&self) -> u64 {
        self.accesses
    }

    /// Distinct pages touched (the faults of an infinite memory).
    pub fn cold(&self) -> u64 {
        self.cold
    }
}

#[cfg(test)]
mod tests {
    use super::Mattson;

    /// LRU simulated directly, for comparison.
    fn lru_faults(stream: &[u64], frames: usize) -> u64 {
        let mut stack: Vec<u64> = Vec::new();
        let mut faults = 0;
        for &p in stream {
            if let Some(i) = stack.iter().position(|&q| q == p) {
                stack.remove(i);
            } else {
                faults += 1;
                if stack.len() == frames {
                    stack.pop();
                }
            }
            stack.insert(0, p);
        }
        faults
    }

    #[test]
    fn one_pass_gives_lru_faults_for_every_size() {
        let mut x = 12345u64;
        let stream: Vec<u64> = (0..20000)
            .map(|i| {
                x = x
                    .wrapping_mul(6364136223846793005)
                    .wrapping_add(1442695040888963407);
                // A hot set and a sweep, so small and large memories differ.
                if i % 3 == 0 {
                    (x >> 33) % 40
                } else {
                    (x >> 33) % 400
                }
            })
            .collect();
        let mut m = Mattson::new(400);
        for &p in &stream {
            m.access(p);
        }
        for frames in [1, 2, 5, 40, 100, 399, 400, 1000] {
            assert_eq!(
                m.faults(frames),
                lru_faults(&stream, frames as usize),
                "{frames}"
            );
        }
        assert_eq!(m.cold(), 400);
        assert_eq!(m.accesses(), 20000);
    }
}
