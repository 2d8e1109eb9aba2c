//! Run-time choice of an AVX2 (or AVX-512) build of a hot method.
//!
//! The hot loops (a constraint's projection, the global step's gather, a block of
//! neighbour queries) are written once, as `#[inline(always)]` portable methods whose loops
//! run over structures of arrays. [`avx2_dispatch!`] compiles such a method a second time
//! with AVX2 enabled, so that those loops run four lanes wide, and picks the build at run
//! time. Without fused multiply-adds both builds perform the same IEEE operations in the
//! same order, so their results are bitwise the same (tested for each use).
//!
//! The neighbour search also has an AVX-512 build, written with explicit intrinsics (mask
//! compares and compress stores) rather than by recompiling the portable loops; it runs
//! where [`has_avx512`] holds.

/// Defines `$name`, which calls the `#[inline(always)]` method `$portable` with the same
/// arguments, compiled for AVX2 (as the private method `$avx2`) where the processor has AVX2
/// and `$allow` holds, and as it is otherwise. The receiver is spelled by the caller
/// (`&self`), so that `$allow` may read it.
macro_rules! avx2_dispatch {
    (
        $(#[$doc:meta])*
        $vis:vis fn $name:ident / $avx2:ident (&$this:ident $(, $arg:ident : $ty:ty)* $(,)?)
            $(-> $ret:ty)? where $allow:expr => $portable:ident
    ) => {
        $(#[$doc])*
        #[inline]
        $vis fn $name(&$this $(, $arg: $ty)*) $(-> $ret)? {
            #[cfg(target_arch = "x86_64")]
            if $allow && std::arch::is_x86_feature_detected!("avx2") {
                // SAFETY: the processor supports AVX2, checked just above.
                return unsafe { $this.$avx2($($arg),*) };
            }
            $this.$portable($($arg),*)
        }

        /// The AVX2 build of the portable method this dispatches to (see `crate::simd`).
        ///
        /// # Safety
        /// The processor must support AVX2.
        #[cfg(target_arch = "x86_64")]
        #[target_feature(enable = "avx2")]
        unsafe fn $avx2(&$this $(, $arg: $ty)*) $(-> $ret)? {
            $this.$portable($($arg),*)
        }
    };
}

pub(crate) use avx2_dispatch;

/// Whether the processor supports what the AVX-512 builds are compiled for: the AVX-512
/// subsets F, VL, DQ and BW, and POPCNT; and the environment variable
/// `PROJFLUID_NO_AVX512` is unset. Setting it makes an AVX-512 processor run the AVX2
/// builds, as a processor without AVX-512 does (for benchmarks, docs/performance.md).
#[cfg(target_arch = "x86_64")]
#[inline]
pub(crate) fn has_avx512() -> bool {
    static USE_AVX512: std::sync::OnceLock<bool> = std::sync::OnceLock::new();
    *USE_AVX512.get_or_init(|| {
        std::env::var_os("PROJFLUID_NO_AVX512").is_none()
            && std::arch::is_x86_feature_detected!("avx512f")
            && std::arch::is_x86_feature_detected!("popcnt")
            && std::arch::is_x86_feature_detected!("avx512vl")
            && std::arch::is_x86_feature_detected!("avx512dq")
            && std::arch::is_x86_feature_detected!("avx512bw")
    })
}
