//! The render skin: a triangle surface embedded in the tet mesh by barycentric
//! coordinates, deformed with it and culled where tets are released (PHYSICS.md §1.4).

use glam::{Mat3, Vec3};
use rayon::prelude::*;

use crate::mesh::{TET_FACES, TetMesh, TriSurface, closest_point_on_triangle};

/// Range to which extrapolated barycentric coordinates are clamped before renormalising.
pub const EXTRAPOLATION_CLAMP: (f32, f32) = (-0.5, 1.5);

/// Barycentric slack under which a point still counts as inside a tet.
const INSIDE_EPS: f32 = 1e-5;

/// Where one skin vertex sits in the tet mesh.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct SkinVertex {
    /// The tet carrying the vertex.
    pub tet: u32,
    /// The tet's node indices (cached so that deformation needs no mesh).
    pub nodes: [u32; 4],
    /// Barycentric weights of the tet's four nodes, summing to 1.
    pub bary: [f32; 4],
}

/// A triangle surface embedded in a tet mesh.
#[derive(Debug, Clone, PartialEq)]
pub struct Skin {
    /// The surface at rest.
    pub surface: TriSurface,
    /// One embedding per surface vertex.
    pub embedding: Vec<SkinVertex>,
    /// Largest distance to the mesh of a vertex that lay outside every tet, m (0 if none).
    pub max_outside_distance: f32,
    /// Number of vertices that lay outside every tet and were extrapolated.
    pub outside_vertices: usize,
}

impl Skin {
    /// Embed `surface` in `mesh`'s rest state: each vertex gets barycentric weights in the
    /// tet containing it, or, outside the mesh, in the nearest tet with its extrapolated
    /// weights clamped to [`EXTRAPOLATION_CLAMP`] and renormalised to sum to 1.
    ///
    /// A non-finite vertex is pinned to node 0 of tet 0 and counts as infinitely far out.
    pub fn embed(mesh: &TetMesh, surface: TriSurface) -> Skin {
        let grid = TetGrid::new(mesh);
        let located: Vec<(SkinVertex, f32)> = surface
            .positions
            .par_iter()
            .map(|&p| grid.locate(mesh, p))
            .collect();
        let outside = located.iter().filter(|(_, d)| *d > 0.0);
        Skin {
            max_outside_distance: outside.clone().map(|&(_, d)| d).fold(0.0, f32::max),
            outside_vertices: outside.count(),
            embedding: located.into_iter().map(|(v, _)| v).collect(),
            surface,
        }
    }

    /// The mesh's boundary triangles as the skin, vertices numbered compactly in order of
    /// first use, each embedded exactly at its node in the tet of the first boundary face
    /// that uses it.
    pub fn from_boundary(mesh: &TetMesh) -> Skin {
        let mut local = vec![u32::MAX; mesh.node_count()];
        let mut positions = Vec::new();
        let mut embedding = Vec::new();
        let mut triangles = Vec::with_capacity(mesh.boundary.len());
        for &(t, f) in &mesh.boundary {
            let tet = mesh.tets[t as usize];
            let tri = TET_FACES[f as usize].map(|corner| {
                let node = tet[corner] as usize;
                if local[node] == u32::MAX {
                    local[node] = positions.len() as u32;
                    positions.push(mesh.rest_positions[node]);
                    let mut bary = [0.0; 4];
                    bary[corner] = 1.0;
                    embedding.push(SkinVertex {
                        tet: t,
                        nodes: tet,
                        bary,
                    });
                }
                local[node]
            });
            triangles.push(tri);
        }
        Skin {
            surface: TriSurface {
                positions,
                triangles,
            },
            embedding,
            max_outside_distance: 0.0,
            outside_vertices: 0,
        }
    }

    /// Deformed skin vertex positions for node positions `positions`, written to `out`
    /// (cleared first).
    ///
    /// # Panics
    /// If `positions` is shorter than the node count of the mesh the skin was embedded in.
    pub fn deform(&self, positions: &[Vec3], out: &mut Vec<Vec3>) {
        out.clear();
        out.par_extend(self.embedding.par_iter().map(|v| {
            (0..4)
                .map(|c| v.bary[c] * positions[v.nodes[c] as usize])
                .sum::<Vec3>()
        }));
    }

    /// Skin triangles none of whose vertices is embedded in a released tet (`released[t]`;
    /// tets past the end of `released` count as live). Triangles naming a vertex the skin
    /// does not have are skipped.
    pub fn visible_triangles<'a>(
        &'a self,
        released: &'a [bool],
    ) -> impl Iterator<Item = [u32; 3]> + 'a {
        self.surface.triangles.iter().copied().filter(move |tri| {
            tri.iter().all(|&v| {
                self.embedding
                    .get(v as usize)
                    .is_some_and(|e| !released.get(e.tet as usize).copied().unwrap_or(false))
            })
        })
    }
}

/// A uniform grid over the mesh's rest bounds; each cell lists the tets whose bounding box
/// overlaps it.
struct TetGrid {
    lo: Vec3,
    inv_cell: f32,
    dims: [usize; 3],
    /// CSR offsets into `items`, one run per cell.
    offsets: Vec<usize>,
    items: Vec<u32>,
    /// Rest bounding box (min, max) of each tet.
    boxes: Vec<(Vec3, Vec3)>,
}

impl TetGrid {
    fn new(mesh: &TetMesh) -> TetGrid {
        let (lo, hi) = mesh.rest_bounds();
        let boxes: Vec<(Vec3, Vec3)> = mesh
            .tets
            .iter()
            .map(|t| {
                let p = t.map(|i| mesh.rest_positions[i as usize]);
                (
                    p[0].min(p[1]).min(p[2].min(p[3])),
                    p[0].max(p[1]).max(p[2].max(p[3])),
                )
            })
            .collect();
        // Cell edge: the mean tet box size, grown if the grid would get much larger than
        // the mesh (sparse meshes in big bounds).
        let extent = (hi - lo).max(Vec3::splat(f32::MIN_POSITIVE));
        let mean_box = boxes
            .iter()
            .map(|(a, b)| (*b - *a).max_element() as f64)
            .sum::<f64>()
            / boxes.len().max(1) as f64;
        let mut cell = (mean_box as f32).max(extent.max_element() * 1e-6);
        let budget = (4 * mesh.tet_count()).max(4096) as f64;
        let dims_for = |cell: f32| {
            extent
                .to_array()
                .map(|e| ((e / cell).ceil() as usize).max(1))
        };
        while dims_for(cell).iter().map(|&d| d as f64).product::<f64>() > budget {
            cell *= 1.25;
        }
        let mut grid = TetGrid {
            lo,
            inv_cell: 1.0 / cell,
            dims: dims_for(cell),
            offsets: Vec::new(),
            items: Vec::new(),
            boxes: Vec::new(),
        };
        let cells = grid.dims.iter().product::<usize>();
        let mut counts = vec![0usize; cells + 1];
        for (a, b) in &boxes {
            grid.for_cells(*a, *b, |c| counts[c + 1] += 1);
        }
        for c in 0..cells {
            counts[c + 1] += counts[c];
        }
        let mut fill = counts.clone();
        grid.items = vec![0; counts[cells]];
        for (t, (a, b)) in boxes.iter().enumerate() {
            let items = &mut grid.items;
            let (lo, inv, dims) = (grid.lo, grid.inv_cell, grid.dims);
            for_cells_in(lo, inv, dims, *a, *b, |c| {
                items[fill[c]] = t as u32;
                fill[c] += 1;
            });
        }
        grid.offsets = counts;
        grid.boxes = boxes;
        grid
    }

    fn for_cells(&self, a: Vec3, b: Vec3, f: impl FnMut(usize)) {
        for_cells_in(self.lo, self.inv_cell, self.dims, a, b, f);
    }

    /// The cell containing `p`, clamped to the grid.
    fn cell_of(&self, p: Vec3) -> usize {
        let mut cell = 0;
        for_cells_in(self.lo, self.inv_cell, self.dims, p, p, |c| cell = c);
        cell
    }

    fn cell_items(&self, c: usize) -> &[u32] {
        &self.items[self.offsets[c]..self.offsets[c + 1]]
    }

    /// The embedding of `p` and its distance outside the mesh (0 when inside).
    fn locate(&self, mesh: &TetMesh, p: Vec3) -> (SkinVertex, f32) {
        let vertex = |t: u32, bary: [f32; 4]| SkinVertex {
            tet: t,
            nodes: mesh.tets[t as usize],
            bary,
        };
        if !p.is_finite() {
            return (vertex(0, [1.0, 0.0, 0.0, 0.0]), f32::INFINITY);
        }
        // Inside: the first candidate in p's cell that contains it, else the one with the
        // largest smallest weight if that is within the slack.
        let mut best: (u32, [f32; 4], f32) = (u32::MAX, [0.0; 4], f32::NEG_INFINITY);
        for &t in self.cell_items(self.cell_of(p)) {
            let bary = barycentric(mesh, t as usize, p);
            let worst = bary.iter().copied().fold(f32::INFINITY, f32::min);
            if worst >= 0.0 {
                return (vertex(t, bary), 0.0);
            }
            if worst > best.2 {
                best = (t, bary, worst);
            }
        }
        if best.2 >= -INSIDE_EPS {
            return (vertex(best.0, best.1), 0.0);
        }

        // Outside: nearest tet, searching boxes p ± d of doubling half-width d. Any tet
        // closer than the best found so far has its box inside p ± best, so once
        // best <= d every closer tet has been seen.
        let grid_hi = self.lo + Vec3::from_array(self.dims.map(|d| d as f32)) / self.inv_cell;
        let mut d = 0.25 / self.inv_cell;
        let mut nearest = (u32::MAX, f32::INFINITY);
        loop {
            let (a, b) = (p - Vec3::splat(d), p + Vec3::splat(d));
            if a.cmple(grid_hi).all() && b.cmpge(self.lo).all() {
                self.for_cells(a, b, |c| {
                    for &t in self.cell_items(c) {
                        let (lo, hi) = self.boxes[t as usize];
                        let gap = (lo - p).max(p - hi).max(Vec3::ZERO);
                        if gap.length_squared() >= nearest.1 * nearest.1 {
                            continue;
                        }
                        let dist = distance_to_tet(mesh, t as usize, p);
                        if dist < nearest.1 {
                            nearest = (t, dist);
                        }
                    }
                });
            }
            let covers_grid = a.cmple(self.lo).all() && b.cmpge(grid_hi).all();
            if nearest.1 <= d || covers_grid || !d.is_finite() {
                break;
            }
            d *= 2.0;
        }
        let (t, dist) = match nearest {
            (u32::MAX, _) => (0, f32::INFINITY),
            found => found,
        };
        (vertex(t, clamped_extrapolation(mesh, t as usize, p)), dist)
    }
}

/// Calls `f` for every cell of a grid (origin `lo`, `1/cell` = `inv`, `dims`) overlapping
/// the box `[a, b]`, clamped to the grid.
fn for_cells_in(lo: Vec3, inv: f32, dims: [usize; 3], a: Vec3, b: Vec3, mut f: impl FnMut(usize)) {
    let cell = |p: Vec3| {
        let q = ((p - lo) * inv).floor().to_array();
        std::array::from_fn::<usize, 3, _>(|k| (q[k].max(0.0) as usize).min(dims[k] - 1))
    };
    let (ca, cb) = (cell(a), cell(b));
    for z in ca[2]..=cb[2] {
        for y in ca[1]..=cb[1] {
            for x in ca[0]..=cb[0] {
                f(x + dims[0] * (y + dims[1] * z));
            }
        }
    }
}

/// Barycentric coordinates of `p` in rest tet `t` (may be negative outside it).
fn barycentric(mesh: &TetMesh, t: usize, p: Vec3) -> [f32; 4] {
    let x0 = mesh.rest_positions[mesh.tets[t][0] as usize];
    barycentric_with(mesh.dm_inv[t], x0, p)
}

fn barycentric_with(dm_inv: Mat3, x0: Vec3, p: Vec3) -> [f32; 4] {
    let l = dm_inv * (p - x0);
    [1.0 - l.x - l.y - l.z, l.x, l.y, l.z]
}

/// Extrapolated weights of `p` in tet `t`, each clamped to [`EXTRAPOLATION_CLAMP`] and
/// renormalised. Should clamping leave the sum below 1/2 (a point many tet sizes away),
/// the weights of the closest point of the tet are used instead.
fn clamped_extrapolation(mesh: &TetMesh, t: usize, p: Vec3) -> [f32; 4] {
    let (lo, hi) = EXTRAPOLATION_CLAMP;
    let bary = barycentric(mesh, t, p).map(|w| w.clamp(lo, hi));
    let sum: f32 = bary.iter().sum();
    if sum >= 0.5 {
        return bary.map(|w| w / sum);
    }
    let closest = closest_point_on_tet(mesh, t, p);
    let bary = barycentric(mesh, t, closest).map(|w| w.clamp(0.0, 1.0));
    let sum: f32 = bary.iter().sum();
    bary.map(|w| w / sum)
}

/// Distance from `p` to rest tet `t` (0 inside).
fn distance_to_tet(mesh: &TetMesh, t: usize, p: Vec3) -> f32 {
    if barycentric(mesh, t, p).iter().all(|&w| w >= 0.0) {
        return 0.0;
    }
    (p - closest_point_on_tet(mesh, t, p)).length()
}

/// Closest point of rest tet `t`'s surface to `p`.
fn closest_point_on_tet(mesh: &TetMesh, t: usize, p: Vec3) -> Vec3 {
    let tet = mesh.tets[t];
    TET_FACES
        .iter()
        .map(|face| {
            let [a, b, c] = face.map(|l| mesh.rest_positions[tet[l] as usize]);
            closest_point_on_triangle(p, a, b, c)
        })
        .min_by(|q, r| {
            (p - *q)
                .length_squared()
                .total_cmp(&(p - *r).length_squared())
        })
        .unwrap_or(p)
}

#[cfg(test)]
mod tests {
    use glam::{Mat3, UVec3};

    use super::*;
    use crate::generate::{IntestineParams, block, intestine};
    use crate::mesh::RawMesh;

    fn cube_mesh() -> TetMesh {
        TetMesh::from_raw(block(Vec3::ZERO, Vec3::ONE, UVec3::new(3, 3, 3)))
            .unwrap()
            .0
    }

    /// Points inside the unit cube, plus two just outside it.
    fn probe_surface() -> TriSurface {
        let mut positions: Vec<Vec3> = (0..200)
            .map(|i| {
                let f = |k: u32| ((i * k + 7) % 97) as f32 / 97.0;
                Vec3::new(f(13), f(31), f(59))
            })
            .collect();
        positions.push(Vec3::new(1.02, 0.5, 0.5));
        positions.push(Vec3::new(0.3, -0.01, 1.01));
        let n = positions.len() as u32;
        TriSurface {
            positions,
            triangles: (0..n - 2).map(|i| [i, i + 1, i + 2]).collect(),
        }
    }

    fn deformed(skin: &Skin, nodes: &[Vec3]) -> Vec<Vec3> {
        let mut out = vec![Vec3::NAN; 3];
        skin.deform(nodes, &mut out);
        out
    }

    #[test]
    fn rest_positions_are_reproduced() {
        let mesh = cube_mesh();
        let skin = Skin::embed(&mesh, probe_surface());
        assert_eq!(skin.outside_vertices, 2);
        assert!((skin.max_outside_distance - 0.02).abs() < 1e-5);
        let out = deformed(&skin, &mesh.rest_positions);
        assert_eq!(out.len(), skin.surface.positions.len());
        for (a, b) in out.iter().zip(&skin.surface.positions) {
            assert!((*a - *b).length() <= 1e-6, "{a} vs {b}");
        }
    }

    #[test]
    fn affine_maps_carry_over_inside_and_outside() {
        let mesh = cube_mesh();
        let skin = Skin::embed(&mesh, probe_surface());
        let a = Mat3::from_cols_array(&[1.2, 0.1, -0.3, 0.2, 0.8, 0.1, 0.0, -0.2, 1.1]);
        let b = Vec3::new(0.5, -1.0, 2.0);
        let nodes: Vec<Vec3> = mesh.rest_positions.iter().map(|&x| a * x + b).collect();
        let out = deformed(&skin, &nodes);
        for (got, rest) in out.iter().zip(&skin.surface.positions) {
            assert!((*got - (a * *rest + b)).length() < 1e-5, "{got} vs {rest}");
        }
    }

    #[test]
    fn far_points_get_clamped_extrapolation() {
        let mesh = cube_mesh();
        let far = Vec3::new(2.5, 0.5, 0.5);
        let skin = Skin::embed(
            &mesh,
            TriSurface {
                positions: vec![far, Vec3::splat(0.5), Vec3::new(1.1, 0.5, 0.5)],
                triangles: vec![[0, 1, 2]],
            },
        );
        let v = skin.embedding[0];
        let (lo, hi) = EXTRAPOLATION_CLAMP;
        // Unclamped, a cell-wide (1/3) tet needs weights of about ±4.5 to reach 1.5 m out.
        let raw = barycentric(&mesh, v.tet as usize, far);
        assert!(raw.iter().any(|&w| !(lo..=hi).contains(&w)), "{raw:?}");
        assert!(
            v.bary.iter().all(|&w| (lo - 1e-6..=hi + 1e-6).contains(&w)),
            "{v:?}"
        );
        assert!((v.bary.iter().sum::<f32>() - 1.0).abs() < 1e-6);
        // The nearest tet touches the x = 1 face, and the reported distance is 1.5 m.
        let x = v.nodes.map(|n| mesh.rest_positions[n as usize].x);
        assert!(x.contains(&1.0), "{x:?}");
        assert!((skin.max_outside_distance - 1.5).abs() < 1e-5);
        assert_eq!(skin.outside_vertices, 2);
        // The mildly outside point is not clamped, so it is reproduced exactly.
        let out = deformed(&skin, &mesh.rest_positions);
        assert!((out[2] - Vec3::new(1.1, 0.5, 0.5)).length() < 1e-6);
        // Far beyond a vertex, clamping alone leaves weights summing to 0, e.g.
        // (-2, 5, -1, -1) -> (-0.5, 1.5, -0.5, -0.5): the tet's closest point is used.
        let unit = RawMesh {
            positions: vec![Vec3::ZERO, Vec3::X, Vec3::Y, Vec3::Z],
            tets: vec![[0, 1, 2, 3]],
            ..RawMesh::default()
        };
        let unit = TetMesh::from_raw(unit).unwrap().0;
        let far = Vec3::new(5.0, -1.0, -1.0);
        let skin = Skin::embed(
            &unit,
            TriSurface {
                positions: vec![far],
                triangles: vec![],
            },
        );
        assert_eq!(skin.embedding[0].bary, [0.0, 1.0, 0.0, 0.0]);
        assert!((skin.max_outside_distance - far.distance(Vec3::X)).abs() < 1e-5);
        // Non-finite points do not panic.
        let skin = Skin::embed(
            &mesh,
            TriSurface {
                positions: vec![Vec3::NAN],
                triangles: vec![],
            },
        );
        assert_eq!(skin.max_outside_distance, f32::INFINITY);
    }

    #[test]
    fn released_tets_hide_their_triangles() {
        let mesh = cube_mesh();
        let skin = Skin::from_boundary(&mesh);
        assert_eq!(skin.surface.triangles.len(), mesh.boundary.len());
        assert_eq!(skin.surface.positions.len(), 4 * 4 * 4 - 2 * 2 * 2);
        let out = deformed(&skin, &mesh.rest_positions);
        assert_eq!(out, skin.surface.positions);
        assert_eq!(skin.visible_triangles(&[]).count(), mesh.boundary.len());

        let mut released = vec![false; mesh.tet_count()];
        let t = skin.embedding[0].tet as usize;
        released[t] = true;
        let visible: Vec<[u32; 3]> = skin.visible_triangles(&released).collect();
        assert!(visible.len() < mesh.boundary.len());
        assert!(!visible.contains(&skin.surface.triangles[0]));
        for tri in &skin.surface.triangles {
            let hit = tri
                .iter()
                .any(|&v| skin.embedding[v as usize].tet as usize == t);
            assert_eq!(visible.contains(tri), !hit);
        }
    }

    #[test]
    fn intestine_skin_embeds_closely() {
        let p = IntestineParams::default();
        let (raw, surface) = intestine(&p);
        let mesh = TetMesh::from_raw(raw).unwrap().0;
        let skin = Skin::embed(&mesh, surface);
        // Skin vertices off the faceted tets are at most a facet's sagitta away.
        let sagitta = p.outer_radius * (1.0 - (std::f32::consts::PI / 32.0).cos());
        assert!(skin.outside_vertices > 0);
        assert!(
            skin.max_outside_distance <= 1.3 * sagitta,
            "{}",
            skin.max_outside_distance
        );
        let out = deformed(&skin, &mesh.rest_positions);
        let err = out
            .iter()
            .zip(&skin.surface.positions)
            .map(|(a, b)| (*a - *b).length())
            .fold(0.0, f32::max);
        assert!(err <= 1e-6 * 0.3, "{err}");
    }
}
