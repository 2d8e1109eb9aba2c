//! The colours of a picture: the background gradient and the speed scale.

/// Background: a vertical gradient from dark slate (top) to near black (bottom).
pub(super) fn background(y: usize, height: usize) -> [f64; 3] {
    let t = y as f64 / height.max(2) as f64;
    let top = [0.16, 0.18, 0.22];
    let bottom = [0.05, 0.05, 0.07];
    std::array::from_fn(|k| top[k] + (bottom[k] - top[k]) * t)
}

/// Speed colour scale: deep blue, light blue, white, orange, red at t = 0, ¼, ½, ¾, 1.
pub(super) fn speed_colour(t: f64) -> [f64; 3] {
    const STOPS: [[f64; 3]; 5] = [
        [0.05, 0.25, 0.75],
        [0.25, 0.65, 0.95],
        [0.92, 0.95, 0.97],
        [1.0, 0.65, 0.2],
        [0.85, 0.15, 0.1],
    ];
    let x = t.clamp(0.0, 1.0) * 4.0;
    let i = (x.floor() as usize).min(3);
    let f = x - i as f64;
    std::array::from_fn(|k| STOPS[i][k] + (STOPS[i + 1][k] - STOPS[i][k]) * f)
}
