//! Fallible reservation: storage a call will need is reserved before the call changes
//! anything, so that a shortage of memory becomes an error (`Error::OutOfMemory`,
//! `PF_ERROR_OUT_OF_MEMORY`) that leaves the world as it was, instead of an abort.

use std::collections::TryReserveError;

/// Makes room in `v` for `total` elements in all (nothing when it has that capacity).
pub(crate) fn reserve_total<T>(v: &mut Vec<T>, total: usize) -> Result<(), TryReserveError> {
    v.try_reserve(total.saturating_sub(v.len()))
}

/// Makes `out` a copy of `from`, reusing its storage; errors when memory for it cannot be
/// had (`out` is then empty).
pub(crate) fn copy_reusing<T: Copy>(out: &mut Vec<T>, from: &[T]) -> Result<(), TryReserveError> {
    out.clear();
    reserve_total(out, from.len())?;
    out.extend_from_slice(from);
    Ok(())
}

/// The error that reports a shortage found by a library that does not say more (a failed
/// allocation inside a factorisation): the one of a request no allocator could grant.
pub(crate) fn shortage() -> TryReserveError {
    Vec::<u8>::new()
        .try_reserve(usize::MAX)
        .expect_err("no allocation has usize::MAX bytes")
}

/// Checks that `bytes` of working memory can be had right now, by allocating and freeing
/// them: for work whose allocations happen deep inside an algorithm (a mesh's sampling, a
/// boundary's sort) and cannot all be reserved one by one. A check, not a reservation.
pub(crate) fn probe(bytes: f64) -> Result<(), TryReserveError> {
    let mut block: Vec<u8> = Vec::new();
    block.try_reserve_exact(bytes.clamp(0.0, isize::MAX as f64) as usize)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn reservations_grow_capacity_and_refuse_the_impossible() {
        let mut v = vec![1u64, 2];
        reserve_total(&mut v, 100).unwrap();
        assert!(v.capacity() >= 100 && v == [1, 2]);
        reserve_total(&mut v, 1).unwrap();
        assert!(reserve_total(&mut v, usize::MAX / 4).is_err());
        assert_eq!(v, [1, 2]);
        probe(1e6).unwrap();
        assert!(probe(1e30).is_err());
        let _: TryReserveError = shortage();
    }
}
