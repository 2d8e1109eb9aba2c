//! Reordering arrays in place by a sort's order, one cycle of the permutation at a time: no
//! second copy of the arrays, at the price of a walk that runs on one thread.

/// The mark a walk through the cycles of an order sets on the slots it has visited: indices
/// of particles stay far below it (a world's particle limit).
const VISITED: u32 = 1 << 31;

/// Reorders data in place so that slot k holds what slot `order[k]` held, through
/// `swap(a, b)`, which exchanges slots a and b of the data: each cycle of the permutation
/// is walked once, with marks on `order` that are cleared at the end.
pub(crate) fn permute_in_place(order: &mut [u32], mut swap: impl FnMut(usize, usize)) {
    assert!(order.len() <= VISITED as usize, "too many slots to mark");
    for start in 0..order.len() {
        let mut k = start;
        while order[k] & VISITED == 0 {
            let from = order[k] as usize;
            order[k] |= VISITED;
            if from == start {
                break;
            }
            swap(k, from);
            k = from;
        }
    }
    order.iter_mut().for_each(|o| *o &= !VISITED);
}

/// Undoes [`permute_in_place`] with the same `order`: slot `order[k]` gets back what slot k
/// holds.
pub(crate) fn unpermute_in_place(order: &mut [u32], mut swap: impl FnMut(usize, usize)) {
    assert!(order.len() <= VISITED as usize, "too many slots to mark");
    for start in 0..order.len() {
        let mut k = start;
        while order[k] & VISITED == 0 {
            let to = order[k] as usize;
            order[k] |= VISITED;
            if to == start {
                break;
            }
            swap(start, to);
            k = to;
        }
    }
    order.iter_mut().for_each(|o| *o &= !VISITED);
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A random permutation of `n` slots.
    fn shuffled(n: usize, seed: u64) -> Vec<u32> {
        let mut rng = crate::random::SplitMix64(seed);
        let mut order: Vec<u32> = (0..n as u32).collect();
        for i in (1..n).rev() {
            let j = (rng.next_f64() * (i + 1) as f64) as usize;
            order.swap(i, j.min(i));
        }
        order
    }

    #[test]
    fn permutations_in_place_reorder_and_put_back() {
        for (n, seed) in [(0, 1), (1, 2), (2, 3), (7, 4), (1000, 5)] {
            let data: Vec<u64> = (0..n as u64).map(|i| i * 31 + 7).collect();
            let order = shuffled(n, seed);
            let expected: Vec<u64> = order.iter().map(|&i| data[i as usize]).collect();
            let (mut permuted, mut marks) = (data.clone(), order.clone());
            permute_in_place(&mut marks, |a, b| permuted.swap(a, b));
            assert_eq!(permuted, expected);
            assert_eq!(marks, order, "the marks are cleared");
            unpermute_in_place(&mut marks, |a, b| permuted.swap(a, b));
            assert_eq!(permuted, data);
            assert_eq!(marks, order);
        }
    }
}
