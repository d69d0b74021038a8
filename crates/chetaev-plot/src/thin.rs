//! Fewer points for a long series, keeping its extremes.

/// At most about `2 · buckets + 2` of `points`, in their order, such that every local extreme a
/// reader would look for is still there: the points are cut, in their order, into `buckets` runs
/// of (nearly) equal length, and of each run the points of least and of greatest `y` are kept, as
/// are the first and the last point. The largest and the smallest `y` of the whole series are
/// therefore always among the points returned (unlike taking every n-th point, which can miss
/// them). Non-finite points, which break a drawn line, are all kept, so the gaps stay.
///
/// With at most `2 · buckets + 2` points, or `buckets == 0`, the points are returned unchanged.
/// For a scatter over x, sort the points by x first, so that each run is a stretch of the x axis.
///
/// ```
/// let pts: Vec<(f64, f64)> = (0..10_000).map(|i| (f64::from(i), f64::from(i % 97))).collect();
/// let few = chetaev_plot::thin(&pts, 100);
/// assert!(few.len() <= 202);
/// assert_eq!(few.iter().map(|p| p.1).fold(0.0, f64::max), 96.0);
/// ```
pub fn thin(points: &[(f64, f64)], buckets: usize) -> Vec<(f64, f64)> {
    let n = points.len();
    if buckets == 0 || n <= 2 * buckets + 2 {
        return points.to_vec();
    }
    let finite = |p: &(f64, f64)| p.0.is_finite() && p.1.is_finite();
    let mut keep = vec![false; n];
    keep[0] = true;
    keep[n - 1] = true;
    for b in 0..buckets {
        let (start, end) = (b * n / buckets, (b + 1) * n / buckets);
        let mut lowest: Option<usize> = None;
        let mut highest: Option<usize> = None;
        for i in start..end {
            let p = &points[i];
            if !finite(p) {
                keep[i] = true;
                continue;
            }
            if lowest.is_none_or(|j| p.1 < points[j].1) {
                lowest = Some(i);
            }
            if highest.is_none_or(|j| p.1 > points[j].1) {
                highest = Some(i);
            }
        }
        for i in lowest.into_iter().chain(highest) {
            keep[i] = true;
        }
    }
    points
        .iter()
        .zip(keep)
        .filter_map(|(p, k)| k.then_some(*p))
        .collect()
}
