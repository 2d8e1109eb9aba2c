//! Parallel reductions whose result does not depend on the thread count: work is split into
//! fixed-size chunks and the chunk results are combined in order.

use rayon::prelude::*;

/// Elements per chunk; fixed so the summation order never depends on the thread count.
const CHUNK: usize = 4096;

/// Chunks summed in parallel at a time, their sums held on the stack, so that a sum
/// allocates nothing (a time step must not abort for want of memory, docs/method.md §1.3).
const GROUP: usize = 256;

/// Σ f(x) over `items`, bitwise identical for any thread count.
pub fn sum<T: Sync>(items: &[T], f: impl Fn(&T) -> f64 + Sync) -> f64 {
    sum_over(items.len(), |i| f(&items[i]))
}

/// Σ f(i) for i in 0..n, bitwise identical for any thread count (same chunks and order as
/// [`sum`]); for sums over several slices at once, such as dot products.
pub fn sum_over(n: usize, f: impl Fn(usize) -> f64 + Sync) -> f64 {
    let chunks = n.div_ceil(CHUNK);
    // The chunks' sums are added in chunk order, starting from the empty sum, exactly as
    // summing them with `Iterator::sum` would.
    let mut total: f64 = std::iter::empty::<f64>().sum();
    let mut partial = [0.0; GROUP];
    for first in (0..chunks).step_by(GROUP) {
        let group = &mut partial[..GROUP.min(chunks - first)];
        group.par_iter_mut().enumerate().for_each(|(k, sum)| {
            let c = first + k;
            *sum = (c * CHUNK..((c + 1) * CHUNK).min(n)).map(&f).sum();
        });
        for sum in group.iter() {
            total += sum;
        }
    }
    total
}

/// max f(x) over `items` (−∞ for none); NaN values propagate as NaN.
pub fn max<T: Sync>(items: &[T], f: impl Fn(&T) -> f64 + Sync + Send) -> f64 {
    max_over(items.len(), |i| f(&items[i]))
}

/// max f(i) for i in 0..n (−∞ for none); NaN values propagate as NaN.
pub fn max_over(n: usize, f: impl Fn(usize) -> f64 + Sync + Send) -> f64 {
    (0..n)
        .into_par_iter()
        .map(f)
        .reduce(|| f64::NEG_INFINITY, nan_max)
}

/// The larger of `a` and `b`, NaN if either is NaN (the combining step of [`max_over`]).
#[inline]
pub fn nan_max(a: f64, b: f64) -> f64 {
    if a.is_nan() || b.is_nan() {
        f64::NAN
    } else {
        a.max(b)
    }
}

#[cfg(test)]
mod tests {
    #[test]
    fn sum_is_independent_of_thread_count() {
        let values: Vec<f64> = (0..100_000)
            .map(|i| ((i * 7919) % 1000) as f64 * 0.1 + 1e-9)
            .collect();
        let run = |threads| {
            rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .unwrap()
                .install(|| super::sum(&values, |v| *v))
        };
        assert_eq!(run(1).to_bits(), run(4).to_bits());
        assert!((run(1) - values.iter().sum::<f64>()).abs() < 1e-6);
        let over = super::sum_over(values.len(), |i| values[i]);
        assert_eq!(over.to_bits(), run(1).to_bits());
        assert!(super::max(&[1.0, f64::NAN, 3.0], |v| *v).is_nan());
        // Over more chunks than one group: the chunks' sums summed in order.
        let n = super::GROUP * super::CHUNK + 3 * super::CHUNK / 2;
        let term = |i: usize| ((i * 7919) % 1000) as f64 * 0.1 + 1e-9;
        let chunks: Vec<f64> = (0..n.div_ceil(super::CHUNK))
            .map(|c| {
                (c * super::CHUNK..((c + 1) * super::CHUNK).min(n))
                    .map(term)
                    .sum()
            })
            .collect();
        let expected: f64 = chunks.iter().sum();
        assert_eq!(super::sum_over(n, term).to_bits(), expected.to_bits());
        let empty: f64 = [0.0; 0].iter().sum();
        assert_eq!(super::sum_over(0, term).to_bits(), empty.to_bits());
        assert_eq!(super::max(&[1.0, 5.0, 3.0], |v| *v), 5.0);
    }
}
