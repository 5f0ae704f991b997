//! The shadow cache (Haines and Greenberg 1986; seed 000 §3.4 cites it as [Hain88]): the last
//! object that blocked a light is tried first on the next shadow ray towards that light, since
//! neighbouring points are often shadowed by the same object. Rayshade keeps one entry per light
//! (and ray depth), tries it, clears it when it misses, and fills it when tracing finds a blocker.
//!
//! The engine sees rays, not lights, so the cache must recognise the light from the ray. Our
//! choice: a shadow ray ends at its light, so the key is the ray's end point o + d·tmax, and two
//! keys name the same light when they are within [`KEY_REL`] of the ray's length (plus the
//! point's magnitude). The workload ends shadow rays a millionth of their length short of the
//! light, well inside that tolerance; two lights closer than that are one light for the cache,
//! which costs hits, never answers. Rays with an infinite `tmax` have no end and bypass the cache.
//!
//! The cache belongs to one `occluded` call (one batch of rays, one thread): no state is shared
//! between threads, and a batch's rays are in shading order, so consecutive rays to a light come
//! from neighbouring points. A hit in the cache is still a real ray–primitive test on the ray's
//! own segment, so the cache changes speed and counters, never an answer.

use crate::ray::Ray;
use glam::Vec3;

/// Lights remembered at once; beyond that the oldest entry is replaced.
pub const SLOTS: usize = 8;

/// Keys within this fraction of the ray's length name the same light.
pub const KEY_REL: f32 = 1e-4;

/// The end point of a shadow ray, and how far another end point may be to match it.
#[derive(Clone, Copy, Debug)]
pub struct Key {
    end: Vec3,
    tol2: f32,
}

impl Key {
    /// The key of `ray`, or `None` when the ray has no end.
    #[inline]
    pub fn of(ray: &Ray) -> Option<Key> {
        if !ray.tmax.is_finite() {
            return None;
        }
        let end = ray.at(ray.tmax);
        let tol = KEY_REL * (ray.dir.length() * ray.tmax + end.abs().max_element());
        end.is_finite().then_some(Key {
            end,
            tol2: tol * tol,
        })
    }
}

/// Last blocker per light, for one batch.
pub struct ShadowCache {
    ends: [Vec3; SLOTS],
    prims: [u32; SLOTS],
    len: usize,
    next: usize,
}

/// A slot whose light is known but whose last ray found no blocker.
const EMPTY: u32 = u32::MAX;

impl Default for ShadowCache {
    fn default() -> Self {
        ShadowCache {
            ends: [Vec3::ZERO; SLOTS],
            prims: [EMPTY; SLOTS],
            len: 0,
            next: 0,
        }
    }
}

impl ShadowCache {
    #[inline(always)]
    fn slot(&self, key: &Key) -> Option<usize> {
        (0..self.len).find(|&i| (self.ends[i] - key.end).length_squared() <= key.tol2)
    }

    /// The primitive that last blocked this light, if any.
    #[inline(always)]
    pub fn blocker(&self, key: &Key) -> Option<u32> {
        self.slot(key)
            .map(|i| self.prims[i])
            .filter(|&p| p != EMPTY)
    }

    /// The cached blocker missed this ray: clear the entry, as Rayshade does.
    pub fn forget(&mut self, key: &Key) {
        if let Some(i) = self.slot(key) {
            self.prims[i] = EMPTY;
        }
    }

    /// Tracing found `prim` blocking this light.
    #[inline]
    pub fn remember(&mut self, key: &Key, prim: u32) {
        let i = match self.slot(key) {
            Some(i) => i,
            None if self.len < SLOTS => {
                self.len += 1;
                self.len - 1
            }
            None => {
                let i = self.next;
                self.next = (self.next + 1) % SLOTS;
                i
            }
        };
        self.ends[i] = key.end;
        self.prims[i] = prim;
    }
}
