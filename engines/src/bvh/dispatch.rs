//! The dispatch table of the BVH traversal kernels: which slab test ([`super::box_test`]) and
//! which triangle packet kernel a tree of width N is traversed with, chosen at run time with
//! `is_x86_feature_detected!`. The whole traversal loop is compiled inside a
//! `#[target_feature]` function for AVX2 so the box test's intrinsics inline.
//!
//! On CPUs with AVX-512 (F, VL, BW, DQ) the same AVX2 traversal is also compiled with those
//! enabled (`isa=auto|avx512`): the source and its operations are the same, so hits, counters
//! and images are the same bits, but the compiler then has 32 vector registers instead of 16
//! and compares into mask registers. The AVX2 loops spill: the bvh8 any-hit kernel read or
//! wrote a vector on the stack in 867 of its ~7,000 instructions (objdump), mostly the
//! watertight triangle test's 20-odd live lanes.

use super::box_test::ScalarPerBox;
use super::traverse::{self, Bvh};
use crate::engine::Counters;
use crate::geometry::lanes::Scalar;
#[cfg(target_arch = "x86_64")]
use crate::geometry::lanes::{Avx8, Sse4};
use crate::geometry::TriangleTest;
use crate::ray::{Hit, Ray};

/// The batch entry points of one traversal kernel.
pub type ClosestFn<const N: usize> = fn(&Bvh<N>, &[Ray], &mut [Hit], TriangleTest, &mut Counters);
pub type AnyFn<const N: usize> = fn(&Bvh<N>, &[Ray], &mut [bool], TriangleTest, &mut Counters);

#[derive(Clone, Copy)]
pub struct Kernels<const N: usize> {
    pub closest: ClosestFn<N>,
    pub any: AnyFn<N>,
    /// SIMD lanes of the box test (0: scalar).
    pub lanes: usize,
    pub name: &'static str,
}

/// The scalar kernels (any width).
pub fn scalar<const N: usize>() -> Kernels<N> {
    Kernels {
        closest: traverse::closest_batch::<N, Scalar, Scalar>,
        any: traverse::any_batch::<N, Scalar, Scalar>,
        lanes: 0,
        name: "scalar",
    }
}

/// The scalar kernels without the per-ray precomputation (`precompute=off`): each box test
/// divides by the direction and orders the slabs itself ([`super::box_test::ScalarPerBox`]).
pub fn scalar_per_box<const N: usize>() -> Kernels<N> {
    Kernels {
        closest: traverse::closest_batch::<N, ScalarPerBox, Scalar>,
        any: traverse::any_batch::<N, ScalarPerBox, Scalar>,
        lanes: 0,
        name: "scalar, no per-ray precomputation",
    }
}

/// SSE kernels for bvh4 (SSE2 is part of x86-64, so always there on that target). On CPUs
/// with AVX2 and FMA the same 4-wide test is compiled with those (fused multiply-subtract, and
/// the whole loop, leaf kernels included, in VEX encoding).
pub fn sse4() -> Option<Kernels<4>> {
    #[cfg(target_arch = "x86_64")]
    {
        Some(if Avx8::available() {
            Kernels {
                closest: x86::fma4_closest,
                any: x86::fma4_any,
                lanes: 4,
                name: "sse+fma",
            }
        } else {
            Kernels {
                closest: traverse::closest_batch::<4, Sse4<false>, Sse4>,
                any: traverse::any_batch::<4, Sse4<false>, Sse4>,
                lanes: 4,
                name: "sse",
            }
        })
    }
    #[cfg(not(target_arch = "x86_64"))]
    {
        None
    }
}

/// AVX2 + FMA kernels for bvh8, when the CPU has both.
pub fn avx8() -> Option<Kernels<8>> {
    #[cfg(target_arch = "x86_64")]
    {
        Avx8::available().then_some(Kernels {
            closest: x86::avx8_closest,
            any: x86::avx8_any,
            lanes: 8,
            name: "avx2",
        })
    }
    #[cfg(not(target_arch = "x86_64"))]
    {
        None
    }
}

/// Whether the CPU has the AVX-512 subsets the `avx512` kernels are compiled with (and AVX2
/// and FMA, which the same code also uses).
pub fn avx512_available() -> bool {
    #[cfg(target_arch = "x86_64")]
    {
        Avx8::available()
            && is_x86_feature_detected!("avx512f")
            && is_x86_feature_detected!("avx512vl")
            && is_x86_feature_detected!("avx512bw")
            && is_x86_feature_detected!("avx512dq")
    }
    #[cfg(not(target_arch = "x86_64"))]
    {
        false
    }
}

/// [`sse4`]'s AVX2 + FMA kernels compiled with AVX-512 too, when the CPU has it.
pub fn sse4_avx512() -> Option<Kernels<4>> {
    #[cfg(target_arch = "x86_64")]
    {
        avx512_available().then_some(Kernels {
            closest: x86::fma4_512_closest,
            any: x86::fma4_512_any,
            lanes: 4,
            name: "sse+fma, avx512",
        })
    }
    #[cfg(not(target_arch = "x86_64"))]
    {
        None
    }
}

/// [`avx8`]'s kernels compiled with AVX-512 too, when the CPU has it.
pub fn avx8_avx512() -> Option<Kernels<8>> {
    #[cfg(target_arch = "x86_64")]
    {
        avx512_available().then_some(Kernels {
            closest: x86::avx8_512_closest,
            any: x86::avx8_512_any,
            lanes: 8,
            name: "avx2, avx512",
        })
    }
    #[cfg(not(target_arch = "x86_64"))]
    {
        None
    }
}

#[cfg(target_arch = "x86_64")]
mod x86 {
    use super::super::traverse::{self, Bvh};
    use crate::engine::Counters;
    use crate::geometry::lanes::{Avx8, Sse4};
    use crate::geometry::TriangleTest;
    use crate::ray::{Hit, Ray};

    /// Feature-checked entry points whose batch loop is compiled with AVX2 and FMA, so the
    /// box test's intrinsics (and the leaf kernels) inline into it.
    macro_rules! avx2_entry {
        ($closest:ident, $closest_impl:ident, $any:ident, $any_impl:ident, $n:literal, $test:ty) => {
            simd_entry!(
                $closest,
                $closest_impl,
                $any,
                $any_impl,
                $n,
                $test,
                "avx2,fma",
                Avx8::available(),
                "this kernel needs AVX2 and FMA"
            );
        };
    }

    /// [`avx2_entry`]'s kernels compiled with AVX-512 F, VL, BW and DQ as well (the same
    /// source: only the registers and encodings the compiler may use differ).
    macro_rules! avx512_entry {
        ($closest:ident, $closest_impl:ident, $any:ident, $any_impl:ident, $n:literal, $test:ty) => {
            simd_entry!(
                $closest,
                $closest_impl,
                $any,
                $any_impl,
                $n,
                $test,
                "avx2,fma,avx512f,avx512vl,avx512bw,avx512dq",
                super::avx512_available(),
                "this kernel needs AVX2, FMA and AVX-512 F, VL, BW, DQ"
            );
        };
    }

    macro_rules! simd_entry {
        (
            $closest:ident,
            $closest_impl:ident,
            $any:ident,
            $any_impl:ident,
            $n:literal,
            $test:ty,
            $features:literal,
            $available:expr,
            $needs:literal
        ) => {
            pub fn $closest(
                bvh: &Bvh<$n>,
                rays: &[Ray],
                hits: &mut [Hit],
                t: TriangleTest,
                c: &mut Counters,
            ) {
                assert!($available, $needs);
                // SAFETY: the CPU has the features (asserted above), all the callee requires.
                unsafe { $closest_impl(bvh, rays, hits, t, c) }
            }

            pub fn $any(
                bvh: &Bvh<$n>,
                rays: &[Ray],
                out: &mut [bool],
                t: TriangleTest,
                c: &mut Counters,
            ) {
                assert!($available, $needs);
                // SAFETY: the CPU has the features (asserted above), all the callee requires.
                unsafe { $any_impl(bvh, rays, out, t, c) }
            }

            #[target_feature(enable = $features)]
            unsafe fn $closest_impl(
                bvh: &Bvh<$n>,
                rays: &[Ray],
                hits: &mut [Hit],
                t: TriangleTest,
                c: &mut Counters,
            ) {
                traverse::closest_batch::<$n, $test, Avx8>(bvh, rays, hits, t, c)
            }

            #[target_feature(enable = $features)]
            unsafe fn $any_impl(
                bvh: &Bvh<$n>,
                rays: &[Ray],
                out: &mut [bool],
                t: TriangleTest,
                c: &mut Counters,
            ) {
                traverse::any_batch::<$n, $test, Avx8>(bvh, rays, out, t, c)
            }
        };
    }

    avx2_entry!(
        avx8_closest,
        avx8_closest_impl,
        avx8_any,
        avx8_any_impl,
        8,
        Avx8
    );
    avx2_entry!(
        fma4_closest,
        fma4_closest_impl,
        fma4_any,
        fma4_any_impl,
        4,
        Sse4<true>
    );
    avx512_entry!(
        avx8_512_closest,
        avx8_512_closest_impl,
        avx8_512_any,
        avx8_512_any_impl,
        8,
        Avx8
    );
    avx512_entry!(
        fma4_512_closest,
        fma4_512_closest_impl,
        fma4_512_any,
        fma4_512_any_impl,
        4,
        Sse4<true>
    );
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::bvh::build_bvh;
    use crate::bvh::config::Config;
    use crate::engine::Settings;
    use crate::geometry::Geometry;
    use glam::Vec3;
    use rtbench_scenes::generate_scene;
    use rtbench_scenes::spd::{Options, Program};

    /// Every kernel this CPU can run gives exactly the scalar kernel's hits and node counts on
    /// the same tree (the SIMD forms only round the entry distances differently, which can
    /// only matter for rays grazing a box; none of these do), on the tree as spheres and cones
    /// and tessellated (triangle packets: SIMD against lane by lane).
    #[test]
    fn every_kernel_matches_scalar() {
        for tessellate in [None, Some(2)] {
            kernels_match_scalar(tessellate);
        }
    }

    fn kernels_match_scalar(tessellate: Option<u32>) {
        let scene = generate_scene(
            Program::Tree,
            &Options {
                size_factor: 4,
                tessellate,
                ..Options::standard(Program::Tree)
            },
        )
        .unwrap();
        let g = Geometry::from_scene(&scene);
        let c = (g.bounds_min + g.bounds_max) * 0.5;
        let r = (g.bounds_max - g.bounds_min).length();
        let rays: Vec<Ray> = (0..400)
            .map(|i| {
                let a = i as f32 * 0.0713;
                let o = c + Vec3::new(a.cos(), 0.4 * (a * 1.7).sin(), a.sin()) * r;
                let t = c + Vec3::new((a * 5.0).sin(), (a * 3.0).cos(), (a * 2.0).sin()) * 0.25 * r;
                Ray::new(o, (t - o).normalize(), 0.0, f32::INFINITY)
            })
            .collect();
        fn run<const N: usize>(
            bvh: &Bvh<N>,
            k: &Kernels<N>,
            rays: &[Ray],
        ) -> (Vec<Hit>, Vec<bool>, Counters) {
            let mut hits = vec![Hit::MISS; rays.len()];
            let mut any = vec![false; rays.len()];
            let mut c = Counters::default();
            (k.closest)(bvh, rays, &mut hits, TriangleTest::Watertight, &mut c);
            (k.any)(
                bvh,
                rays,
                &mut any,
                TriangleTest::Watertight,
                &mut Counters::default(),
            );
            (hits, any, c)
        }
        let config = |w: usize| Config::parse(w, Settings::new("bvh", vec![])).unwrap();
        let (bvh4, _) = build_bvh::<4>(&g, &config(4)).unwrap();
        let want4 = run(&bvh4, &scalar::<4>(), &rays);
        assert!(want4.0.iter().filter(|h| h.is_hit()).count() > 100);
        // Without the per-ray precomputation: the same hits (node counts may differ by a
        // grazing box, the test being widened by a few ulps).
        let per_box = run(&bvh4, &scalar_per_box::<4>(), &rays);
        assert_eq!((&per_box.0, &per_box.1), (&want4.0, &want4.1));
        let mut fours: Vec<Kernels<4>> = sse4().into_iter().collect();
        #[cfg(target_arch = "x86_64")]
        fours.push(Kernels {
            closest: traverse::closest_batch::<4, Sse4<false>, Sse4>,
            any: traverse::any_batch::<4, Sse4<false>, Sse4>,
            lanes: 4,
            name: "sse",
        });
        for k in &fours {
            assert_eq!(run(&bvh4, k, &rays), want4, "{}", k.name);
        }
        if let Some(k) = sse4_avx512() {
            assert_eq!(run(&bvh4, &k, &rays), want4, "{}", k.name);
        }
        let (bvh8, _) = build_bvh::<8>(&g, &config(8)).unwrap();
        let want8 = run(&bvh8, &scalar::<8>(), &rays);
        for k in avx8().into_iter().chain(avx8_avx512()) {
            assert_eq!(run(&bvh8, &k, &rays), want8, "{}", k.name);
        }
    }
}
