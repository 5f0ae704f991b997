//! The one vocabulary of SIMD lanes for the box and the triangle tests: each type names an
//! instruction set and a lane count, once. The BVH's ray–N-box slab test
//! ([`crate::bvh::box_test::ChildTest`]) and the triangle packet test
//! ([`super::triangle_simd::PacketKernel`]) are both implemented for these types, so `Sse4`
//! means the same lanes in both (as Embree's `vfloat4`/`vfloat8` serve its box and triangle
//! kernels alike).
//!
//! - [`Scalar`]: one lane at a time, any width (the `simd=off` fallback and the reference).
//! - [`Sse4`]: 4 lanes in 128-bit registers (SSE2, part of the x86-64 baseline). `Sse4<true>`
//!   lets the box test fuse its multiply and subtract (FMA); it is only compiled inside code
//!   that has checked [`Avx8::available`]. The triangle test never fuses (it rounds exactly as
//!   the scalar kernels), so it is implemented for `Sse4` (`Sse4<false>`) only.
//! - [`Avx8`]: 8 lanes in 256-bit registers (AVX2 + FMA); only for code that has checked
//!   [`Avx8::available`].

/// One lane at a time, any width.
pub struct Scalar;

/// 4 lanes, SSE (`FMA`: the box test may fuse multiply and subtract; see the module doc).
pub struct Sse4<const FMA: bool = false>;

/// 8 lanes, AVX2 + FMA.
pub struct Avx8;

impl Avx8 {
    /// Whether the CPU has AVX2 and FMA: what the 8-lane forms (and the 4-lane forms compiled
    /// into the same AVX2 + FMA traversal) need.
    pub fn available() -> bool {
        #[cfg(target_arch = "x86_64")]
        {
            is_x86_feature_detected!("avx2") && is_x86_feature_detected!("fma")
        }
        #[cfg(not(target_arch = "x86_64"))]
        {
            false
        }
    }
}
