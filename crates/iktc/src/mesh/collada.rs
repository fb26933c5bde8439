//! Reading Collada (`.dae`) meshes into one welded [`TriMesh`] in metres, z up.
//!
//! What is read (COLLADA 1.4/1.5, the subset robot descriptions use):
//!
//! * `<library_geometries>/<geometry>/<mesh>`: the positions are the `<source>` that the
//!   `<vertices>`' `<input semantic="POSITION">` names; vertex `i` is the three numbers at
//!   `offset + i·stride` of its `<float_array>`, `offset`, `stride` and `count` from the
//!   `<accessor>`. Normals and texture coordinates are ignored.
//! * The primitives `<triangles>`, `<polylist>` (one polygon per `<vcount>` entry),
//!   `<polygons>` and `<trifans>` (one polygon or fan per `<p>`) and `<tristrips>` (one strip per
//!   `<p>`). A `<p>` holds `k` indices per corner, `k` = 1 + the largest `offset` of the
//!   primitive's `<input>`s; the corner's position is the index at the `offset` of its
//!   `<input semantic="VERTEX">`. A polygon `v₀ … vₙ₋₁` is cut into the fan
//!   `(v₀, vᵢ, vᵢ₊₁)`, `i = 1 … n−2`; a strip's triangle `i` is `(vᵢ, vᵢ₊₁, vᵢ₊₂)` for even `i` and
//!   `(vᵢ₊₁, vᵢ, vᵢ₊₂)` for odd `i`, so every triangle keeps the polygon's counter-clockwise turn.
//! * The scene: the `<visual_scene>` that `<scene>/<instance_visual_scene>` names (else the first
//!   one). A `<node>`'s transform is the product `T = T₁·T₂·…·Tₙ` of its `<matrix>` (16 numbers,
//!   row-major), `<translate>` (x y z), `<rotate>` (axis x y z, angle in degrees, right-handed)
//!   and `<scale>` (x y z) children in document order; a nested node's world transform is
//!   `W = W_parent·T`, and each `<instance_geometry url="#id">` places geometry `id` at `W`; an
//!   `<instance_node url="#id">` walks node `id` (of `<library_nodes>` or a visual scene) as a
//!   child. Without a visual scene every geometry is taken once, untransformed.
//!   `<instance_controller>` (skinned meshes), external URLs, `<lookat>`, `<skew>` and `<ph>`
//!   (polygons with holes) are left out with a warning; `<lines>` and `<linestrips>` (no
//!   surface) are ignored, as normals and texture coordinates are.
//! * Bounds: at most [`MAX_DEPTH`] nested elements and nested nodes (`<instance_node>` hops
//!   counted, so a node that instances itself is an error, not a stack overflow), at most
//!   [`MAX_NODES`] nodes entered and [`MAX_TRIANGLES`] triangles placed.
//! * `<asset>`: a point `p` of the file becomes `p' = U·(m·p)` with `m` the `<unit meter>` (1
//!   without one) and `U` the rotation that takes the file's `<up_axis>` to z up. After the
//!   COLLADA specification's axes (right, up, toward the viewer): `Y_UP` is (+x, +y, +z), `Z_UP`
//!   (+x, +z, −y), `X_UP` (−y, +x, +z). Sending right → +x, up → +z, toward the viewer → −y gives
//!   `Y_UP: (x, y, z) ↦ (x, −z, y)` (+90° about x), `Z_UP: (x, y, z) ↦ (x, y, z)` and
//!   `X_UP: (x, y, z) ↦ (−y, −z, x)` (−y ↦ +x, x ↦ +z, z ↦ −y; determinant +1).
//! * Winding: a triangle `(a, b, c)` maps to `(Fa, Fb, Fc)` with `F` the whole affine map; when
//!   the determinant of `F`'s linear part is negative (a mirror), `b` and `c` are swapped so
//!   the triangle stays counter-clockwise seen from outside (its outward normal
//!   `(b−a)×(c−a)` would otherwise point inwards).
//!
//! All instanced triangles form one soup, welded as an STL is ([`TriMesh::weld`]).

use std::collections::hash_map::Entry;
use std::collections::HashMap;

use nalgebra::{Matrix3, Matrix4, Rotation3, Unit, Vector3, Vector4};

use super::xml::{bad, by_url, count_attr, floats, indices, parse_tree, Element};
use super::TriMesh;
use crate::error::Result;

/// The deepest element nesting read \[elements\]; deeper files are refused (nodes are walked
/// recursively, and real scenes nest a few dozen levels at most).
pub const MAX_DEPTH: usize = 256;

/// The most nodes a scene walk enters \[nodes\], each `<instance_node>` hop counted anew:
/// bounds the walk of a file whose nodes instance each other many times over.
pub const MAX_NODES: usize = 1_000_000;

/// The most triangles a file may place \[triangles\]: 4 M triangles are 144 MB as `f32`
/// corners, far above a robot link's visual mesh (a UR5e upper arm: 40 124).
pub const MAX_TRIANGLES: usize = 4_000_000;

/// A Collada file read into one mesh.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct ColladaMesh {
    /// The instanced geometry in metres, z up, welded.
    pub mesh: TriMesh,
    /// One line per part of the file left out (an `<instance_node>`, a `<ph>`, …).
    pub warnings: Vec<String>,
}

/// The positions of `source` \[file unit\]: three numbers per accessor element.
fn positions(source: &Element, name: &str) -> Result<Vec<[f64; 3]>> {
    let array = source.child("float_array").ok_or_else(|| {
        bad(
            name,
            source.line,
            format!(
                "{} has no <float_array>; positions must be floats",
                source.describe()
            ),
        )
    })?;
    let declared = count_attr(array, "count", None, name)?;
    let data = floats(array, Some(declared), name)?;
    let accessor = source
        .child("technique_common")
        .and_then(|t| t.child("accessor"))
        .ok_or_else(|| {
            bad(
                name,
                source.line,
                format!("{} has no <technique_common><accessor>", source.describe()),
            )
        })?;
    let count = count_attr(accessor, "count", None, name)?;
    let stride = count_attr(accessor, "stride", Some(1), name)?;
    let offset = count_attr(accessor, "offset", Some(0), name)?;
    if stride < 3 {
        return Err(bad(
            name,
            accessor.line,
            format!(
                "<accessor> of {}: stride=\"{stride}\", expected at least 3 (x y z per position)",
                source.describe()
            ),
        ));
    }
    let needed = count
        .checked_sub(1)
        .map_or(Some(0), |last| {
            last.checked_mul(stride)
                .and_then(|s| s.checked_add(offset))
                .and_then(|s| s.checked_add(3))
        })
        .unwrap_or(usize::MAX);
    if needed > data.len() {
        return Err(bad(
            name,
            accessor.line,
            format!(
                "<accessor count=\"{count}\" stride=\"{stride}\" offset=\"{offset}\"> of {} needs \
                 {needed} numbers, expected at most the {} of {}",
                source.describe(),
                data.len(),
                array.describe()
            ),
        ));
    }
    Ok((0..count)
        .map(|i| {
            let b = offset + i * stride;
            [data[b], data[b + 1], data[b + 2]]
        })
        .collect())
}

/// A mesh's positions \[file unit\] and triangles (indices into them).
#[derive(Debug, Default)]
struct Geometry {
    positions: Vec<[f64; 3]>,
    triangles: Vec<[usize; 3]>,
}

/// How a `<p>`'s corners form triangles.
#[derive(Clone, Copy)]
enum Shape {
    Fan,
    Strip,
}

/// Appends the triangles of one polygon, fan or strip `corners` (position indices).
fn triangulate(corners: &[usize], shape: Shape, out: &mut Vec<[usize; 3]>) {
    for i in 0..corners.len().saturating_sub(2) {
        out.push(match shape {
            Shape::Fan => [corners[0], corners[i + 1], corners[i + 2]],
            Shape::Strip if i % 2 == 0 => [corners[i], corners[i + 1], corners[i + 2]],
            Shape::Strip => [corners[i + 1], corners[i], corners[i + 2]],
        });
    }
}

/// One primitive's index layout: indices per corner and the offset of the position index.
fn layout(prim: &Element, what: &str, name: &str) -> Result<(usize, usize)> {
    let mut stride = 1;
    let mut vertex = None;
    for input in prim.all("input") {
        let offset = count_attr(input, "offset", Some(0), name)?;
        stride = stride.max(offset.saturating_add(1));
        if input.attr("semantic") == Some("VERTEX") {
            vertex = Some(offset);
        }
    }
    let vertex = vertex.ok_or_else(|| {
        bad(
            name,
            prim.line,
            format!("{what}: no <input semantic=\"VERTEX\">, expected one naming the positions"),
        )
    })?;
    Ok((stride, vertex))
}

/// The position indices of `p` for a primitive of index stride `stride`, checked against the
/// `n` positions.
fn corners(
    p: &Element,
    (stride, vertex): (usize, usize),
    n: usize,
    what: &str,
    name: &str,
) -> Result<Vec<usize>> {
    let raw = indices(p, name)?;
    if raw.len() % stride != 0 {
        return Err(bad(
            name,
            p.line,
            format!(
                "{what}: <p> holds {} indices, expected a multiple of {stride} (indices per \
                 corner)",
                raw.len()
            ),
        ));
    }
    raw.chunks_exact(stride)
        .map(|c| c[vertex])
        .map(|i| {
            if i < n {
                Ok(i)
            } else {
                Err(bad(
                    name,
                    p.line,
                    format!(
                        "{what}: <p> has the position index {i}, expected less than the {n} \
                         positions"
                    ),
                ))
            }
        })
        .collect()
}

/// The triangles of `geometry`; `Ok(None)` (with a warning) for one without a `<mesh>`.
fn read_geometry(
    geometry: &Element,
    name: &str,
    warnings: &mut Vec<String>,
) -> Result<Option<Geometry>> {
    let gid = geometry.describe();
    let Some(mesh) = geometry.child("mesh") else {
        warnings.push(format!(
            "{gid} has no <mesh> (a <convex_mesh> or <spline>?); left out"
        ));
        return Ok(None);
    };
    let mut g = Geometry {
        positions: positions(mesh_positions(mesh, &gid, name)?, name)?,
        triangles: Vec::new(),
    };
    let n = g.positions.len();
    for prim in &mesh.children {
        let what = format!("{gid}, <{}>", prim.tag);
        match prim.tag.as_str() {
            "triangles" => read_triangles(prim, n, &what, name, &mut g.triangles)?,
            "polylist" => read_polylist(prim, n, &what, name, &mut g.triangles)?,
            "polygons" | "trifans" | "tristrips" => {
                let lay = layout(prim, &what, name)?;
                let shape = if prim.tag == "tristrips" {
                    Shape::Strip
                } else {
                    Shape::Fan
                };
                for p in prim.all("p") {
                    triangulate(&corners(p, lay, n, &what, name)?, shape, &mut g.triangles);
                }
                if prim.child("ph").is_some() {
                    warnings.push(format!(
                        "{what}: polygons with holes (<ph>) are not read; left out"
                    ));
                }
            }
            _ => {}
        }
    }
    Ok(Some(g))
}

/// The `<source>` of `mesh` that its `<vertices>` names as the positions (`gid` describes the
/// geometry in errors).
fn mesh_positions<'a>(mesh: &'a Element, gid: &str, name: &str) -> Result<&'a Element> {
    let sources: Vec<&Element> = mesh.all("source").collect();
    let vertices = mesh.child("vertices").ok_or_else(|| {
        bad(
            name,
            mesh.line,
            format!("{gid}: <mesh> has no <vertices>, expected one naming the positions"),
        )
    })?;
    let url = vertices
        .all("input")
        .find(|i| i.attr("semantic") == Some("POSITION"))
        .and_then(|i| i.attr("source"))
        .ok_or_else(|| {
            bad(
                name,
                vertices.line,
                format!("{gid}: <vertices> has no <input semantic=\"POSITION\" source=…>"),
            )
        })?;
    by_url(&sources, url).ok_or_else(|| {
        bad(
            name,
            vertices.line,
            format!("{gid}: <vertices> names the positions {url}, expected the id of a <source> of the mesh"),
        )
    })
}

/// Appends the triangles of a `<triangles>` primitive over `n` positions; its `<p>` must hold
/// `3 × count` corners.
fn read_triangles(
    prim: &Element,
    n: usize,
    what: &str,
    name: &str,
    triangles: &mut Vec<[usize; 3]>,
) -> Result<()> {
    let lay = layout(prim, what, name)?;
    let Some(p) = prim.child("p") else {
        return Ok(());
    };
    let c = corners(p, lay, n, what, name)?;
    let count = count_attr(prim, "count", Some(c.len() / 3), name)?;
    if c.len() != 3 * count {
        return Err(bad(
            name,
            p.line,
            format!(
                "{what}: <p> holds {} corners, expected 3 × count = {}",
                c.len(),
                count.saturating_mul(3)
            ),
        ));
    }
    c.chunks_exact(3)
        .for_each(|t| triangles.push([t[0], t[1], t[2]]));
    Ok(())
}

/// Appends the triangles (fans) of a `<polylist>` primitive over `n` positions; its `<p>` must
/// hold the sum of `<vcount>` corners.
fn read_polylist(
    prim: &Element,
    n: usize,
    what: &str,
    name: &str,
    triangles: &mut Vec<[usize; 3]>,
) -> Result<()> {
    let lay = layout(prim, what, name)?;
    let Some(p) = prim.child("p") else {
        return Ok(());
    };
    let c = corners(p, lay, n, what, name)?;
    let vcount = match prim.child("vcount") {
        Some(v) => indices(v, name)?,
        None => Vec::new(),
    };
    let total = vcount.iter().try_fold(0usize, |s, &k| s.checked_add(k));
    if total != Some(c.len()) {
        return Err(bad(
            name,
            p.line,
            format!(
                "{what}: <p> holds {} corners, expected the sum of <vcount> ({})",
                c.len(),
                total.map_or("overflowing".into(), |t| t.to_string())
            ),
        ));
    }
    let mut at = 0;
    for k in vcount {
        triangulate(&c[at..at + k], Shape::Fan, triangles);
        at += k;
    }
    Ok(())
}

/// The transform of `node`'s own transform elements, in document order.
fn node_transform(node: &Element, name: &str, warnings: &mut Vec<String>) -> Result<Matrix4<f64>> {
    let mut t = Matrix4::identity();
    for c in &node.children {
        let m = match c.tag.as_str() {
            "matrix" => Matrix4::from_row_slice(&floats(c, Some(16), name)?),
            "translate" => {
                let v = floats(c, Some(3), name)?;
                Matrix4::new_translation(&Vector3::new(v[0], v[1], v[2]))
            }
            "scale" => {
                let v = floats(c, Some(3), name)?;
                Matrix4::new_nonuniform_scaling(&Vector3::new(v[0], v[1], v[2]))
            }
            "rotate" => {
                let v = floats(c, Some(4), name)?;
                let axis = Vector3::new(v[0], v[1], v[2]);
                if axis.norm() == 0.0 {
                    return Err(bad(
                        name,
                        c.line,
                        "<rotate> has the axis (0, 0, 0), expected a non-zero axis",
                    ));
                }
                Rotation3::from_axis_angle(&Unit::new_normalize(axis), v[3].to_radians())
                    .to_homogeneous()
            }
            "lookat" | "skew" => {
                warnings.push(format!(
                    "{}: <{}> is not read; the node is placed without it",
                    node.describe(),
                    c.tag
                ));
                continue;
            }
            _ => continue,
        };
        t *= m;
    }
    Ok(t)
}

/// The walk over a visual scene's nodes: what it can reach and what it has collected.
struct Walk<'a> {
    name: &'a str,
    /// The index among the file's geometries of each geometry id.
    geometry_ids: HashMap<&'a str, usize>,
    /// The nodes an `<instance_node>` may name: those of `<library_nodes>` and of the visual
    /// scenes, by id.
    nodes: HashMap<&'a str, &'a Element>,
    /// Nodes entered so far (counted against [`MAX_NODES`]).
    visited: usize,
    /// The geometry instances: world transform and index into `geometries`.
    instances: Vec<(Matrix4<f64>, usize)>,
    warnings: Vec<String>,
}

impl<'a> Walk<'a> {
    fn new(root: &'a Element, name: &'a str, geometries: &'a [&'a Element]) -> Walk<'a> {
        let mut nodes = HashMap::new();
        let mut todo: Vec<&Element> = root
            .all("library_nodes")
            .chain(root.all("library_visual_scenes"))
            .flat_map(|l| l.children.iter())
            .collect();
        while let Some(e) = todo.pop() {
            if e.tag == "node" {
                if let Some(id) = e.attr("id") {
                    nodes.entry(id).or_insert(e);
                }
            }
            todo.extend(e.all("node"));
        }
        let mut geometry_ids = HashMap::new();
        for (i, g) in geometries.iter().enumerate() {
            if let Some(id) = g.attr("id") {
                geometry_ids.entry(id).or_insert(i);
            }
        }
        Walk {
            name,
            geometry_ids,
            nodes,
            visited: 0,
            instances: Vec::new(),
            warnings: Vec::new(),
        }
    }

    /// Collects the geometry instances under `node` placed at `parent`·(its transform);
    /// `depth` counts the nodes above it, `<instance_node>` hops included.
    fn node(&mut self, node: &'a Element, parent: &Matrix4<f64>, depth: usize) -> Result<()> {
        let name = self.name;
        self.visited += 1;
        if self.visited > MAX_NODES {
            return Err(bad(
                name,
                node.line,
                format!(
                    "the scene enters more than {MAX_NODES} nodes (counting each \
                     <instance_node> anew); expected at most that"
                ),
            ));
        }
        if depth > MAX_DEPTH {
            return Err(bad(
                name,
                node.line,
                format!(
                    "{}: nodes nest deeper than {MAX_DEPTH} (through <instance_node>: a node \
                     that instances itself?)",
                    node.describe()
                ),
            ));
        }
        let world = parent * node_transform(node, name, &mut self.warnings)?;
        for c in &node.children {
            let url = c.attr("url").unwrap_or("");
            let id = url.strip_prefix('#');
            match c.tag.as_str() {
                "node" => self.node(c, &world, depth + 1)?,
                "instance_node" => match id.and_then(|id| self.nodes.get(id).copied()) {
                    Some(target) => self.node(target, &world, depth + 1)?,
                    None => self.warnings.push(format!(
                        "{}: <instance_node url=\"{url}\"> names no <node> of this file; left out",
                        node.describe()
                    )),
                },
                "instance_geometry" => match id.and_then(|id| self.geometry_ids.get(id)) {
                    Some(&g) => self.instances.push((world, g)),
                    None => self.warnings.push(format!(
                        "{}: <instance_geometry url=\"{url}\"> names no <geometry> of this \
                         file; left out",
                        node.describe()
                    )),
                },
                "instance_controller" => self.warnings.push(format!(
                    "{}: <instance_controller> (a skinned mesh) is not read; left out",
                    node.describe()
                )),
                _ => {}
            }
        }
        Ok(())
    }
}

/// The map `p ↦ U·(m·p)` of the file's `<asset>`: unit `m` \[m per file unit\], up axis `U`.
fn asset_transform(root: &Element, name: &str) -> Result<Matrix4<f64>> {
    let asset = root.child("asset");
    let mut m = 1.0;
    if let Some(unit) = asset.and_then(|a| a.child("unit")) {
        if let Some(v) = unit.attr("meter") {
            m = v
                .trim()
                .parse::<f64>()
                .ok()
                .filter(|x| x.is_finite() && *x > 0.0)
                .ok_or_else(|| {
                    bad(
                        name,
                        unit.line,
                        format!(
                            "<unit meter=\"{v}\">: expected a positive finite number of metres"
                        ),
                    )
                })?;
        }
    }
    let up = match asset.and_then(|a| a.child("up_axis")) {
        None => Matrix3::identity(),
        Some(u) => match u.text.trim() {
            "Y_UP" => Matrix3::new(1.0, 0.0, 0.0, 0.0, 0.0, -1.0, 0.0, 1.0, 0.0),
            "Z_UP" => Matrix3::identity(),
            "X_UP" => Matrix3::new(0.0, -1.0, 0.0, 0.0, 0.0, -1.0, 1.0, 0.0, 0.0),
            other => {
                return Err(bad(
                    name,
                    u.line,
                    format!("<up_axis> is `{other}`, expected X_UP, Y_UP or Z_UP"),
                ))
            }
        },
    };
    Ok((up * m).to_homogeneous())
}

/// Reads a Collada file's bytes; `name` names the source in errors.
///
/// # Errors
/// [`Error::Parse`](crate::error::Error::Parse) (naming the file, the line and the element) for bytes that are not XML or
/// not Collada, a file without `<geometry>` or without triangles, a `<float_array>` whose
/// `count` is not its number of values, a number that is not finite, an accessor or a `<p>`
/// index beyond the positions, a `<p>` or `<vcount>` that does not fit its primitive, a
/// `<node>` transform with the wrong number of values, and a nesting deeper than
/// [`MAX_DEPTH`].
pub fn read_collada(bytes: &[u8], name: &str) -> Result<ColladaMesh> {
    let root = collada_root(bytes, name)?;
    let asset = asset_transform(&root, name)?;
    let geometries: Vec<&Element> = root
        .all("library_geometries")
        .flat_map(|l| l.all("geometry"))
        .collect();
    if geometries.is_empty() {
        return Err(bad(
            name,
            root.line,
            "no <library_geometries>/<geometry>: nothing to draw",
        ));
    }
    let scene = chosen_scene(&root, name)?;
    let mut walk = Walk::new(&root, name, &geometries);
    match scene {
        Some(s) => {
            for node in s.all("node") {
                walk.node(node, &Matrix4::identity(), 1)?;
            }
        }
        None => walk
            .instances
            .extend((0..geometries.len()).map(|g| (Matrix4::identity(), g))),
    }
    let Walk {
        instances,
        mut warnings,
        ..
    } = walk;
    // Each geometry is read once, however often it is instanced.
    let mut read: HashMap<usize, Option<Geometry>> = HashMap::new();
    let mut soup = Vec::new();
    for (world, i) in instances {
        let g = geometries[i];
        let geometry = match read.entry(i) {
            Entry::Occupied(e) => e.into_mut(),
            Entry::Vacant(e) => e.insert(read_geometry(g, name, &mut warnings)?),
        };
        if let Some(geometry) = geometry {
            place_geometry(g, geometry, &(asset * world), name, &mut soup)?;
        }
    }
    if soup.is_empty() {
        return Err(bad(
            name,
            root.line,
            "no triangles: the scene places no <geometry> with <triangles>, <polylist>, \
             <polygons>, <trifans> or <tristrips>",
        ));
    }
    Ok(ColladaMesh {
        mesh: TriMesh::weld(&soup),
        warnings,
    })
}

/// The element tree of the Collada file `bytes`: UTF-8 text (a leading byte-order mark
/// skipped) whose root element is `<COLLADA>`.
fn collada_root(bytes: &[u8], name: &str) -> Result<Element> {
    let text = std::str::from_utf8(bytes).map_err(|e| {
        bad(
            name,
            0,
            format!("not a Collada file: the bytes are not UTF-8 text ({e}); a binary mesh?"),
        )
    })?;
    let text = text.strip_prefix('\u{feff}').unwrap_or(text);
    let root = parse_tree(text, name)?;
    if root.tag != "COLLADA" {
        return Err(bad(
            name,
            root.line,
            format!(
                "not a Collada file: the root element is <{}>, expected <COLLADA>",
                root.tag
            ),
        ));
    }
    Ok(root)
}

/// The visual scene to draw: the one `<scene>/<instance_visual_scene>` names, else the first.
fn chosen_scene<'a>(root: &'a Element, name: &str) -> Result<Option<&'a Element>> {
    let scenes: Vec<&Element> = root
        .all("library_visual_scenes")
        .flat_map(|l| l.all("visual_scene"))
        .collect();
    let chosen = root
        .child("scene")
        .and_then(|s| s.child("instance_visual_scene"));
    Ok(match chosen {
        Some(inst) => {
            let url = inst.attr("url").unwrap_or("");
            Some(by_url(&scenes, url).ok_or_else(|| {
                bad(
                    name,
                    inst.line,
                    format!("<instance_visual_scene url=\"{url}\">: expected the id of a <visual_scene> of this file"),
                )
            })?)
        }
        None => scenes.first().copied(),
    })
}

/// Appends to `soup` the triangles of `geometry` (read from the element `g`) placed by `f`
/// (file units to metres, Z up), kept counter-clockwise under a mirror; non-finite
/// coordinates and more than [`MAX_TRIANGLES`] in all are errors.
fn place_geometry(
    g: &Element,
    geometry: &Geometry,
    f: &Matrix4<f64>,
    name: &str,
    soup: &mut Vec<[[f32; 3]; 3]>,
) -> Result<()> {
    let mirror = f.fixed_view::<3, 3>(0, 0).determinant() < 0.0;
    let placed: Vec<[f32; 3]> = geometry
        .positions
        .iter()
        .map(|p| {
            let q = f * Vector4::new(p[0], p[1], p[2], 1.0);
            [q.x as f32, q.y as f32, q.z as f32]
        })
        .collect();
    if let Some(q) = placed.iter().find(|q| q.iter().any(|x| !x.is_finite())) {
        return Err(bad(
            name,
            g.line,
            format!(
                "{} placed by its node reaches {q:?}, expected finite coordinates in metres",
                g.describe()
            ),
        ));
    }
    if soup.len() + geometry.triangles.len() > MAX_TRIANGLES {
        return Err(bad(
            name,
            g.line,
            format!(
                "the scene places more than {MAX_TRIANGLES} triangles (at {}); expected at \
                 most that",
                g.describe()
            ),
        ));
    }
    for t in &geometry.triangles {
        let (a, b, c) = (placed[t[0]], placed[t[1]], placed[t[2]]);
        soup.push(if mirror { [a, c, b] } else { [a, b, c] });
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::xml::line_at;

    /// Tolerance on coordinates and volumes computed in `f32` \[m, m³\]: a few ulps of the
    /// unit-sized values the tests use.
    const TOL: f64 = 1e-5;

    /// Corner `i` of the unit cube: bit 0 is x, bit 1 y, bit 2 z.
    fn corner(i: usize) -> [f64; 3] {
        [(i & 1) as f64, ((i >> 1) & 1) as f64, ((i >> 2) & 1) as f64]
    }

    /// The cube's faces, counter-clockwise seen from outside (checked by the signed volume).
    const QUADS: [[usize; 4]; 6] = [
        [0, 2, 3, 1],
        [4, 5, 7, 6],
        [0, 1, 5, 4],
        [2, 6, 7, 3],
        [0, 4, 6, 2],
        [1, 3, 7, 5],
    ];

    fn joined(v: impl IntoIterator<Item = String>) -> String {
        v.into_iter().collect::<Vec<_>>().join(" ")
    }

    /// The cube's positions as a `<source>` plus `<vertices>`.
    fn source() -> String {
        let nums = joined((0..8).flat_map(|i| corner(i).map(|x| x.to_string())));
        format!(
            r##"<source id="pos"><float_array id="pos-array" count="24">{nums}</float_array>
            <technique_common><accessor source="#pos-array" count="8" stride="3">
            <param name="X" type="float"/><param name="Y" type="float"/><param name="Z" type="float"/>
            </accessor></technique_common></source>
            <vertices id="verts"><input semantic="POSITION" source="#pos"/></vertices>"##
        )
    }

    /// The cube as `<triangles>`, each corner with a normal index at offset 1 (so `<p>` has
    /// two indices per corner).
    fn triangles() -> String {
        let p =
            joined(QUADS.iter().enumerate().flat_map(|(f, q)| {
                [q[0], q[1], q[2], q[0], q[2], q[3]].map(|v| format!("{v} {f}"))
            }));
        format!(
            r##"<triangles count="12"><input semantic="VERTEX" source="#verts" offset="0"/>
            <input semantic="NORMAL" source="#nrm" offset="1"/><p>{p}</p></triangles>"##
        )
    }

    /// The cube as one `<polylist>` of quads.
    fn polylist() -> String {
        let p = joined(QUADS.iter().flatten().map(|v| v.to_string()));
        format!(
            r##"<polylist count="6"><input semantic="VERTEX" source="#verts" offset="0"/>
            <vcount>4 4 4 4 4 4</vcount><p>{p}</p></polylist>"##
        )
    }

    /// The cube as `<polygons>`, `<trifans>` or `<tristrips>`, one `<p>` a face.
    fn per_face(tag: &str) -> String {
        let p = joined(QUADS.iter().map(|q| {
            let order = if tag == "tristrips" {
                [q[0], q[1], q[3], q[2]]
            } else {
                *q
            };
            format!("<p>{}</p>", joined(order.map(|v| v.to_string())))
        }));
        format!(
            r##"<{tag} count="6"><input semantic="VERTEX" source="#verts" offset="0"/>{p}</{tag}>"##
        )
    }

    /// A Collada file with `asset` inside `<asset>`, the cube geometry of primitives `prims`,
    /// and `scene` after the libraries.
    fn dae(asset: &str, prims: &str, scene: &str) -> String {
        format!(
            r##"<?xml version="1.0" encoding="utf-8"?>
<COLLADA xmlns="http://www.collada.org/2005/11/COLLADASchema" version="1.4.1">
  <asset>{asset}</asset>
  <library_geometries>
    <geometry id="cube" name="cube"><mesh>{src}
{prims}
    </mesh></geometry>
  </library_geometries>
{scene}
</COLLADA>
"##,
            src = source()
        )
    }

    /// A visual scene with one node of body `body`, chosen by `<scene>`.
    fn scene(body: &str) -> String {
        format!(
            r##"<library_visual_scenes><visual_scene id="s"><node id="n">{body}</node>
            </visual_scene></library_visual_scenes>
            <scene><instance_visual_scene url="#s"/></scene>"##
        )
    }

    const INSTANCE: &str = r##"<instance_geometry url="#cube"/>"##;

    fn read(text: &str) -> ColladaMesh {
        read_collada(text.as_bytes(), "t.dae").unwrap()
    }

    fn error(text: &str) -> String {
        read_collada(text.as_bytes(), "bad.dae")
            .unwrap_err()
            .to_string()
    }

    /// The signed volume `Σ a·(b×c) / 6` (divergence theorem) \[m³\]: positive for a closed
    /// mesh whose triangles are counter-clockwise seen from outside.
    fn volume(m: &TriMesh) -> f64 {
        m.triangles
            .iter()
            .map(|t| {
                let [a, b, c] = t.map(|i| m.vertices[i as usize].map(f64::from));
                let bc = [
                    b[1] * c[2] - b[2] * c[1],
                    b[2] * c[0] - b[0] * c[2],
                    b[0] * c[1] - b[1] * c[0],
                ];
                (a[0] * bc[0] + a[1] * bc[1] + a[2] * bc[2]) / 6.0
            })
            .sum()
    }

    fn assert_box(m: &TriMesh, lo: [f64; 3], hi: [f64; 3]) {
        let (a, b) = m.bounding_box().unwrap();
        for k in 0..3 {
            assert!(
                (f64::from(a[k]) - lo[k]).abs() < TOL && (f64::from(b[k]) - hi[k]).abs() < TOL,
                "box {a:?}..{b:?}, expected {lo:?}..{hi:?}"
            );
        }
    }

    #[test]
    fn the_cube_reads_the_same_from_every_primitive() {
        for prims in [
            triangles(),
            polylist(),
            per_face("polygons"),
            per_face("trifans"),
            per_face("tristrips"),
        ] {
            // Without a visual scene: the geometry untransformed.
            let m = read(&dae("", &prims, ""));
            assert!(m.warnings.is_empty(), "{:?}", m.warnings);
            assert_eq!(m.mesh.vertices.len(), 8, "{prims}");
            assert_eq!(m.mesh.triangles.len(), 12, "{prims}");
            assert_box(&m.mesh, [0.0; 3], [1.0; 3]);
            assert!((volume(&m.mesh) - 1.0).abs() < TOL, "{prims}");
            // Every position is one of the cube's corners.
            for v in &m.mesh.vertices {
                assert!(v.iter().all(|&x| x == 0.0 || x == 1.0), "{v:?}");
            }
        }
    }

    #[test]
    fn fans_and_strips_follow_the_collada_corner_rules() {
        // Fan (v₀, vᵢ, vᵢ₊₁); strip (vᵢ, vᵢ₊₁, vᵢ₊₂) for even i, (vᵢ₊₁, vᵢ, vᵢ₊₂) for odd i.
        let mut fan = Vec::new();
        triangulate(&[7, 8, 9, 10, 11], Shape::Fan, &mut fan);
        assert_eq!(fan, vec![[7, 8, 9], [7, 9, 10], [7, 10, 11]]);
        let mut strip = Vec::new();
        triangulate(&[7, 8, 9, 10, 11], Shape::Strip, &mut strip);
        assert_eq!(strip, vec![[7, 8, 9], [9, 8, 10], [9, 10, 11]]);
        let mut none = Vec::new();
        triangulate(&[7, 8], Shape::Strip, &mut none);
        assert!(none.is_empty());
    }

    #[test]
    fn triangles_without_a_count_take_their_count_from_p() {
        let m = read(&dae("", &triangles().replace(" count=\"12\"", ""), "")).mesh;
        assert_eq!(m.triangles.len(), 12);
        assert!((volume(&m) - 1.0).abs() < TOL);
    }

    #[test]
    fn numbers_in_cdata_read_as_text() {
        let cdata = dae("", &triangles(), "")
            .replace("count=\"24\">", "count=\"24\"><![CDATA[")
            .replace("</float_array>", "]]></float_array>");
        assert!(cdata.contains("<![CDATA[0 0 0 1 0 0"), "{cdata}");
        let m = read(&cdata).mesh;
        assert_eq!(m.triangles.len(), 12);
        assert_box(&m, [0.0; 3], [1.0; 3]);
    }

    #[test]
    fn lines_are_counted_from_one() {
        let text = "a\nb\nc";
        assert_eq!(
            [0, 1, 2, 3, 4, 99].map(|p| line_at(text, p)),
            [1, 1, 2, 2, 3, 3]
        );
        // A mismatched end tag on line 3 is reported there.
        let e = error("<COLLADA>\n<asset>\n</COLLADA>\n");
        assert!(
            e.starts_with("bad.dae:3:") && e.contains("not well-formed"),
            "{e}"
        );
    }

    #[test]
    fn node_transforms_compose_in_document_order_and_parent_first() {
        // p' = T·R·S·p with S = diag(2, 1, 1), R = 90° about z, T = (1, 2, 3): the box
        // [0,2]×[0,1]×[0,1] turned to [−1,0]×[0,2]×[0,1], then moved.
        let body = format!(
            r#"<translate>1 2 3</translate><rotate>0 0 1 90</rotate><scale>2 1 1</scale>{INSTANCE}"#
        );
        let m = read(&dae("", &triangles(), &scene(&body))).mesh;
        assert_box(&m, [0.0, 2.0, 3.0], [1.0, 4.0, 4.0]);
        assert!((volume(&m) - 2.0).abs() < TOL);
        // Corner (1, 0, 0) ↦ S (2, 0, 0) ↦ R (0, 2, 0) ↦ T (1, 4, 3).
        assert!(m.vertices.iter().any(|v| {
            (v[0] - 1.0).abs() < 1e-5 && (v[1] - 4.0).abs() < 1e-5 && (v[2] - 3.0).abs() < 1e-5
        }));
        // The same translation as a row-major <matrix>, inside a parent lifted by 10 in z.
        let nested = format!(
            r#"<translate>0 0 10</translate><node id="child">
            <matrix>1 0 0 1 0 1 0 2 0 0 1 3 0 0 0 1</matrix><rotate>0 0 1 90</rotate>
            <scale>2 1 1</scale>{INSTANCE}</node>"#
        );
        let n = read(&dae("", &triangles(), &scene(&nested))).mesh;
        assert_box(&n, [0.0, 2.0, 13.0], [1.0, 4.0, 14.0]);
    }

    #[test]
    fn the_unit_scales_to_metres() {
        let m = read(&dae(
            r#"<unit name="millimeter" meter="0.001"/>"#,
            &polylist(),
            "",
        ))
        .mesh;
        assert_box(&m, [0.0; 3], [0.001; 3]);
        assert!((volume(&m) - 1e-9).abs() < 1e-15);
        let e = error(&dae(r#"<unit meter="-1"/>"#, &polylist(), ""));
        assert!(
            e.contains("bad.dae:3") && e.contains("positive finite"),
            "{e}"
        );
    }

    #[test]
    fn the_up_axis_becomes_z() {
        // The box [0,1]×[0,2]×[0,3] (scaled by a node) shows where each axis goes.
        let body = format!("<scale>1 2 3</scale>{INSTANCE}");
        let up = |axis: &str| {
            read(&dae(
                &format!("<up_axis>{axis}</up_axis>"),
                &triangles(),
                &scene(&body),
            ))
            .mesh
        };
        // Z_UP: unchanged.
        let z = up("Z_UP");
        assert_box(&z, [0.0; 3], [1.0, 2.0, 3.0]);
        // Y_UP: (x, y, z) ↦ (x, −z, y): the file's up (y) is z, its viewer direction (z) is −y.
        let y = up("Y_UP");
        assert_box(&y, [0.0, -3.0, 0.0], [1.0, 0.0, 2.0]);
        // X_UP: (x, y, z) ↦ (−y, −z, x): up (x) is z, right (−y) is x, toward the viewer (z) −y.
        let x = up("X_UP");
        assert_box(&x, [-2.0, -3.0, 0.0], [0.0, 0.0, 1.0]);
        // A rotation: no mirror, the volume stays +6.
        for m in [&z, &y, &x] {
            assert!((volume(m) - 6.0).abs() < TOL);
        }
        // The file's corner (1, 2, 3) lands at (1, −3, 2) (Y_UP) and (−2, −3, 1) (X_UP).
        assert!(y.vertices.contains(&[1.0, -3.0, 2.0]));
        assert!(x.vertices.contains(&[-2.0, -3.0, 1.0]));
        let e = error(&dae("<up_axis>W_UP</up_axis>", &triangles(), ""));
        assert!(e.contains("W_UP") && e.contains("Y_UP"), "{e}");
    }

    #[test]
    fn a_mirror_keeps_the_triangles_counter_clockwise() {
        for mirror in ["-1 1 1", "1 1 -1", "-1 -1 -1"] {
            let body = format!("<scale>{mirror}</scale>{INSTANCE}");
            let m = read(&dae("", &polylist(), &scene(&body))).mesh;
            assert_eq!(m.triangles.len(), 12);
            // Without the swap the signed volume would be −1.
            assert!((volume(&m) - 1.0).abs() < TOL, "{mirror}: {}", volume(&m));
        }
        // Two mirrors are a rotation: no swap.
        let body = format!("<scale>-1 -1 1</scale>{INSTANCE}");
        let m = read(&dae("", &polylist(), &scene(&body))).mesh;
        assert!((volume(&m) - 1.0).abs() < TOL);
    }

    #[test]
    fn instances_place_the_geometry_once_each_and_unread_parts_are_warned() {
        let body = format!(
            r##"{INSTANCE}<node id="again"><translate>5 0 0</translate>{INSTANCE}</node>
            <instance_node url="#elsewhere"/><instance_geometry url="#missing"/>"##
        );
        let m = read(&dae("", &triangles(), &scene(&body)));
        assert_eq!(m.mesh.triangles.len(), 24);
        assert_eq!(m.mesh.vertices.len(), 16);
        assert_box(&m.mesh, [0.0; 3], [6.0, 1.0, 1.0]);
        assert!((volume(&m.mesh) - 2.0).abs() < TOL);
        assert_eq!(m.warnings.len(), 2, "{:?}", m.warnings);
        assert!(m.warnings[0].contains("<instance_node url=\"#elsewhere\"> names no <node>"));
        assert!(m.warnings[1].contains("#missing"));
        let holes =
            per_face("polygons").replace("</polygons>", "<ph><p>0 1 2</p><h>3</h></ph></polygons>");
        let h = read(&dae("", &holes, ""));
        assert_eq!(h.mesh.triangles.len(), 12);
        assert!(h.warnings[0].contains("<ph>"), "{:?}", h.warnings);
    }

    /// The cube geometry, `<library_nodes>` of `library`, and a visual scene of `body`.
    fn with_library(prims: &str, library: &str, body: &str) -> String {
        dae("", prims, &scene(body)).replace(
            "<library_visual_scenes>",
            &format!("<library_nodes>{library}</library_nodes><library_visual_scenes>"),
        )
    }

    #[test]
    fn instance_node_places_a_library_node_under_the_instancing_node() {
        // part = translate (0, 0, 5) · cube; placed twice, at x = 10 and turned 90° about z.
        let library = format!(r#"<node id="part"><translate>0 0 5</translate>{INSTANCE}</node>"#);
        let body = r##"<translate>10 0 0</translate><instance_node url="#part"/>
            <node id="turned"><rotate>0 0 1 90</rotate><instance_node url="#part"/></node>"##;
        let m = read(&with_library(&triangles(), &library, body));
        assert!(m.warnings.is_empty(), "{:?}", m.warnings);
        assert_eq!(m.mesh.triangles.len(), 24);
        // First at [10,11]×[0,1]×[5,6]; the second, under the node at x = 10 turned 90°,
        // at [9,10]×[0,1]×[5,6]: together [9,11]×[0,1]×[5,6].
        assert_box(&m.mesh, [9.0, 0.0, 5.0], [11.0, 1.0, 6.0]);
        assert!((volume(&m.mesh) - 2.0).abs() < TOL);
    }

    #[test]
    fn runaway_node_instancing_is_an_error() {
        // A node that instances itself.
        let library = r##"<node id="loop"><instance_node url="#loop"/></node>"##;
        let e = error(&with_library(
            &triangles(),
            library,
            r##"<instance_node url="#loop"/>"##,
        ));
        assert!(
            e.contains("<node id=\"loop\">") && e.contains("deeper than"),
            "{e}"
        );
        // 25 levels each instancing the next twice: 2²⁵ nodes.
        let mut library = String::from(r#"<node id="n0"/>"#);
        for k in 1..=25 {
            let j = k - 1;
            library.push_str(&format!(
                r##"<node id="n{k}"><instance_node url="#n{j}"/><instance_node url="#n{j}"/></node>"##
            ));
        }
        let e = error(&with_library(
            &triangles(),
            &library,
            r##"<instance_node url="#n25"/>"##,
        ));
        assert!(e.contains(&format!("more than {MAX_NODES} nodes")), "{e}");
        // 2¹² instances of a 1000-corner polygon (998 triangles): 4 087 808 triangles.
        let p = joined((0..1000).map(|i| (i % 8).to_string()));
        let big = format!(
            r##"<polylist count="1"><input semantic="VERTEX" source="#verts" offset="0"/>
            <vcount>1000</vcount><p>{p}</p></polylist>"##
        );
        let mut library = format!(r#"<node id="n0">{INSTANCE}</node>"#);
        for k in 1..=12 {
            let j = k - 1;
            library.push_str(&format!(
                r##"<node id="n{k}"><instance_node url="#n{j}"/><instance_node url="#n{j}"/></node>"##
            ));
        }
        let e = error(&with_library(
            &big,
            &library,
            r##"<instance_node url="#n12"/>"##,
        ));
        assert!(
            e.contains(&format!("more than {MAX_TRIANGLES} triangles")),
            "{e}"
        );
    }

    #[test]
    fn input_that_is_not_collada_is_an_error() {
        let e = read_collada(&[0x80, 0x81, 0, 7], "bin.dae")
            .unwrap_err()
            .to_string();
        assert!(e.contains("bin.dae") && e.contains("not UTF-8"), "{e}");
        let e = error("<COLLADA><asset></COLLADA>");
        assert!(e.contains("not well-formed XML"), "{e}");
        let e = error("<COLLADA><asset>");
        assert!(e.contains("never closed"), "{e}");
        let e = error("solid cube\nendsolid\n");
        assert!(e.contains("no XML element"), "{e}");
        let e = error("<robot name=\"r\"/>");
        assert!(
            e.contains("root element is <robot>, expected <COLLADA>"),
            "{e}"
        );
        let e = error(
            &dae("", "", "")
                .replace("<library_geometries>", "<library_x>")
                .replace("</library_geometries>", "</library_x>"),
        );
        assert!(e.contains("no <library_geometries>/<geometry>"), "{e}");
        let e = error(&dae("", "", ""));
        assert!(e.contains("no triangles"), "{e}");
        let n = MAX_DEPTH + 1;
        let deep = format!("<COLLADA>{}{}</COLLADA>", "<a>".repeat(n), "</a>".repeat(n));
        let e = error(&deep);
        assert!(
            e.contains("nested") && e.contains(&MAX_DEPTH.to_string()),
            "{e}"
        );
    }

    #[test]
    fn malformed_meshes_are_errors_naming_the_element() {
        let good = dae("", &triangles(), "");
        let cases: [(String, &[&str]); 9] = [
            // One number missing from the array.
            (
                good.replace("count=\"24\"", "count=\"25\""),
                &["<float_array id=\"pos-array\">", "24 numbers, expected 25"],
            ),
            (
                good.replacen("0 0 0 1 0 0", "0 0 0 NaN 0 0", 1),
                &["pos-array", "number 3 is `NaN`", "finite"],
            ),
            (
                good.replacen("0 0 0 1 0 0", "0 0 0 inf 0 0", 1),
                &["number 3 is `inf`"],
            ),
            // The accessor asks for more positions than the array holds.
            (
                good.replace("count=\"8\" stride=\"3\"", "count=\"9\" stride=\"3\""),
                &["<accessor count=\"9\"", "needs 27 numbers", "24"],
            ),
            (
                good.replace("count=\"8\" stride=\"3\"", "count=\"8\" stride=\"2\""),
                &["stride=\"2\"", "at least 3"],
            ),
            // A position index of 8 among 8 positions.
            (
                good.replacen("<p>0 0 ", "<p>8 0 ", 1),
                &[
                    "<geometry id=\"cube\">, <triangles>",
                    "index 8",
                    "less than the 8 positions",
                ],
            ),
            (good.replacen("<p>0 0 ", "<p>0 0 1 ", 1), &["multiple of 2"]),
            (
                good.replace("count=\"12\"", "count=\"13\""),
                &["36 corners", "3 × count = 39"],
            ),
            (
                good.replace("semantic=\"VERTEX\"", "semantic=\"POSITION\""),
                &["no <input semantic=\"VERTEX\">"],
            ),
        ];
        for (text, wants) in cases {
            let e = error(&text);
            assert!(e.starts_with("bad.dae:"), "{e}");
            for w in wants {
                assert!(e.contains(w), "{e}\nexpected it to name {w}");
            }
        }
        let e = error(&dae(
            "",
            &polylist().replace("4 4 4 4 4 4", "4 4 4 4 4 3"),
            "",
        ));
        assert!(
            e.contains("24 corners") && e.contains("sum of <vcount> (23)"),
            "{e}"
        );
        let body = format!("<rotate>0 0 0 90</rotate>{INSTANCE}");
        let e = error(&dae("", &polylist(), &scene(&body)));
        assert!(e.contains("axis (0, 0, 0)"), "{e}");
        let body = format!("<matrix>1 0 0 0</matrix>{INSTANCE}");
        let e = error(&dae("", &polylist(), &scene(&body)));
        assert!(e.contains("<matrix> holds 4 numbers, expected 16"), "{e}");
        let body = format!("<scale>1e300 1 1</scale><scale>1e300 1 1</scale>{INSTANCE}");
        let e = error(&dae("", &polylist(), &scene(&body)));
        assert!(e.contains("finite coordinates"), "{e}");
        // The line of the element is named: the float_array is on line 5.
        let e = error(&good.replace("count=\"24\"", "count=\"25\""));
        assert!(e.starts_with("bad.dae:5:"), "{e}");
    }
}
