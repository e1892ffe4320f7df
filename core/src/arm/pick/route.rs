//! The way the base drives to a stance round what stands between: A* on a 5 cm grid of the
//! ground, the car a circle round its arm base (its body's far corner, clearance included), the
//! world's objects as their rectangles; the cells near the start and the stance are free (the
//! body was checked there exactly, and the go-to-point law makes the last approach). The path
//! is cut to the corners a straight drive needs (line of sight).

use std::cmp::Ordering;
use std::collections::{BinaryHeap, HashMap};

use nalgebra::Vector2;

use super::ground::Footprint;

/// Grid cell size (m).
const CELL_M: f64 = 0.05;
/// How far beyond the start and the goal the grid reaches (m).
const MARGIN_M: f64 = 1.5;
/// Cells this close to the start or the goal (m) are free.
const FREE_NEAR_M: f64 = 0.35;
/// The most cells A* expands before it gives up.
const MAX_EXPANDED: usize = 200_000;

/// A grid cell (column, row).
type Cell = (i32, i32);

/// An open cell and its estimated total cost, for the heap (smallest first).
#[derive(Debug, PartialEq)]
struct Open(f64, Cell);

impl Eq for Open {}

impl PartialOrd for Open {
    fn partial_cmp(&self, other: &Self) -> Option<Ordering> {
        Some(self.cmp(other))
    }
}

impl Ord for Open {
    fn cmp(&self, other: &Self) -> Ordering {
        other
            .0
            .total_cmp(&self.0)
            .then_with(|| other.1.cmp(&self.1))
    }
}

/// The grid the route is searched on.
struct Grid<'a> {
    origin: Vector2<f64>,
    size: (i32, i32),
    start: Vector2<f64>,
    goal: Vector2<f64>,
    radius_m: f64,
    obstacles: &'a [Footprint],
}

impl Grid<'_> {
    fn centre(&self, (i, j): Cell) -> Vector2<f64> {
        self.origin + Vector2::new(f64::from(i) + 0.5, f64::from(j) + 0.5) * CELL_M
    }

    fn cell(&self, p: Vector2<f64>) -> Cell {
        let q = (p - self.origin) / CELL_M;
        (q.x.floor() as i32, q.y.floor() as i32)
    }

    /// Whether the car's circle at `p` stays clear of every obstacle (free near the ends).
    fn free(&self, p: Vector2<f64>) -> bool {
        (p - self.start).norm() <= FREE_NEAR_M
            || (p - self.goal).norm() <= FREE_NEAR_M
            || self
                .obstacles
                .iter()
                .all(|o| o.distance_to(p) > self.radius_m)
    }

    fn inside(&self, (i, j): Cell) -> bool {
        i >= 0 && j >= 0 && i < self.size.0 && j < self.size.1
    }

    /// Whether the straight drive from `a` to `b` stays free (sampled every half cell).
    fn line_free(&self, a: Vector2<f64>, b: Vector2<f64>) -> bool {
        let n = ((b - a).norm() / (CELL_M / 2.0)).ceil().max(1.0) as usize;
        (0..=n).all(|k| self.free(a + (b - a) * (k as f64 / n as f64)))
    }
}

/// The corners (world x, y, m) a car of `radius_m` round its arm base drives through from
/// `start` to `goal` round `obstacles`: empty when the straight drive is free; an error when
/// no way is found on the grid.
pub(super) fn route(
    start: Vector2<f64>,
    goal: Vector2<f64>,
    radius_m: f64,
    obstacles: &[Footprint],
) -> Result<Vec<Vector2<f64>>, String> {
    let lo = start.inf(&goal) - Vector2::repeat(MARGIN_M);
    let hi = start.sup(&goal) + Vector2::repeat(MARGIN_M);
    let cells = ((hi - lo) / CELL_M).map(|v| v.ceil() as i32);
    let grid = Grid {
        origin: lo,
        size: (cells.x, cells.y),
        start,
        goal,
        radius_m,
        obstacles,
    };
    if grid.line_free(start, goal) {
        return Ok(Vec::new());
    }
    let (from, to) = (grid.cell(start), grid.cell(goal));
    let mut open = BinaryHeap::from([Open(0.0, from)]);
    let mut cost: HashMap<Cell, f64> = HashMap::from([(from, 0.0)]);
    let mut came: HashMap<Cell, Cell> = HashMap::new();
    let mut expanded = 0;
    while let Some(Open(_, cell)) = open.pop() {
        if cell == to {
            return Ok(corners(&grid, &came, to));
        }
        expanded += 1;
        if expanded > MAX_EXPANDED {
            break;
        }
        let here = cost.get(&cell).copied().unwrap_or(f64::INFINITY);
        for (di, dj) in [
            (1, 0),
            (-1, 0),
            (0, 1),
            (0, -1),
            (1, 1),
            (1, -1),
            (-1, 1),
            (-1, -1),
        ] {
            let next = (cell.0 + di, cell.1 + dj);
            if !grid.inside(next) || !grid.free(grid.centre(next)) {
                continue;
            }
            let step = if di != 0 && dj != 0 {
                std::f64::consts::SQRT_2
            } else {
                1.0
            };
            let through = here + step * CELL_M;
            if through < cost.get(&next).copied().unwrap_or(f64::INFINITY) {
                cost.insert(next, through);
                came.insert(next, cell);
                let left = (grid.centre(next) - goal).norm();
                open.push(Open(through + left, next));
            }
        }
    }
    Err(format!(
        "no way round what stands between ({:.2}, {:.2}) and ({:.2}, {:.2}) m for a car {:.2} m round",
        start.x, start.y, goal.x, goal.y, radius_m
    ))
}

/// The grid path to `to`, cut to the corners a straight drive needs (without the start and the
/// goal itself).
fn corners(grid: &Grid<'_>, came: &HashMap<Cell, Cell>, to: Cell) -> Vec<Vector2<f64>> {
    let mut path = vec![grid.goal];
    let mut cell = to;
    while let Some(&prev) = came.get(&cell) {
        path.push(grid.centre(prev));
        cell = prev;
    }
    path.push(grid.start);
    path.reverse();
    let mut out = Vec::new();
    let mut from = grid.start;
    let mut k = 1;
    while k < path.len() - 1 {
        // The furthest point still in sight of `from`.
        let mut far = k;
        while far + 1 < path.len() && grid.line_free(from, path[far + 1]) {
            far += 1;
        }
        if far == path.len() - 1 {
            break;
        }
        out.push(path[far]);
        from = path[far];
        k = far + 1;
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A 0.4 m wall across the straight way: the route goes round it, every corner and every
    /// leg between them clear of it by the car's radius; with nothing between, no corners.
    #[test]
    fn the_route_goes_round_a_wall_between() {
        let wall = Footprint {
            centre: Vector2::new(1.0, 0.0),
            half: Vector2::new(0.05, 0.4),
            yaw_rad: 0.0,
        };
        let (start, goal) = (Vector2::new(0.0, 0.0), Vector2::new(2.0, 0.0));
        assert_eq!(route(start, goal, 0.2, &[]), Ok(Vec::new()));
        let corners = route(start, goal, 0.2, &[wall]).unwrap_or_default();
        assert!(!corners.is_empty());
        let mut points = vec![start];
        points.extend(&corners);
        points.push(goal);
        for leg in points.windows(2) {
            for k in 0..=50 {
                let p = leg[0] + (leg[1] - leg[0]) * (f64::from(k) / 50.0);
                assert!(wall.distance_to(p) > 0.2 - 1e-9, "{p:?} on {corners:?}");
            }
        }
        // A wall the car cannot pass: closed all round.
        let ring: Vec<Footprint> = (0..4)
            .map(|k| {
                let a = f64::from(k) * std::f64::consts::FRAC_PI_2;
                Footprint {
                    centre: Vector2::new(2.0 + a.cos(), a.sin()),
                    half: Vector2::new(0.05, 1.1),
                    yaw_rad: a,
                }
            })
            .collect();
        assert!(route(start, goal, 0.2, &ring).is_err());
    }
}
