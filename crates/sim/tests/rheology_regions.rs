//! Per-region materials: an organ whose outer layer is viscoelastic and whose core is
//! rheological, built from one mesh, behaves between its two materials.

mod rheology_support;

use glam::Vec3;
use incise_sim::mesh::EdgeList;
use incise_sim::rheology::{
    FlatIndenter, MaterialMap, MaterialRegion, PressProtocol, RegionShape, RheologyBody, Specimen,
    press_and_release,
};
use incise_sim::selection::NodeSelection;
use rheology_support::preset;

#[test]
fn layered_block_keeps_less_dent_than_its_core_material_alone() {
    let protocol = PressProtocol::standard(Specimen::standard(), 0.5);
    let specimen = protocol.specimen.mesh().unwrap();
    let mesh = &specimen.mesh;
    let edges = EdgeList::of_mesh(mesh);
    // Core: everything more than one cell (5 cm) inside the sides and below the top.
    let core = MaterialRegion {
        shape: RegionShape::Nodes(NodeSelection::Box {
            min: Vec3::new(-0.101, -0.101, -0.001),
            max: Vec3::new(0.101, 0.101, 0.101),
        }),
        material: 1,
    };
    let materials = [preset("viscoelastic"), preset("rheological")];
    let map = MaterialMap::from_regions(mesh, &edges, 0, &[core], materials.len()).unwrap();
    let core_edges = map.edge_material.iter().filter(|&&m| m == 1).count();
    assert!(core_edges > 0 && core_edges < edges.len());
    let mut body = RheologyBody::new(mesh, &materials, map).unwrap();
    // Edges of each region carry their material's clamps.
    for e in 0..edges.len() {
        let want = if body.material_map().edge_material[e] == 1 {
            (0.8, 1.0)
        } else {
            (1.0, 1.0)
        };
        assert_eq!(body.ratio_bounds(e), want);
    }
    body.pin(&specimen.bottom);
    body.set_indenter(Some(FlatIndenter {
        centre: [0.0, 0.0],
        half_size: protocol.indenter_half_size,
        rest_top: protocol.specimen.size.z,
        schedule: protocol.schedule,
        candidates: specimen.top.clone(),
    }));
    body.advance(protocol.duration()).unwrap();
    let layered = specimen.centre_depth(&body);
    let core_alone = press_and_release(&preset("rheological"), &protocol)
        .unwrap()
        .residual_depth();
    eprintln!(
        "residual dent: layered {:.2} mm, rheological alone {:.2} mm",
        layered * 1e3,
        core_alone * 1e3
    );
    assert!(
        layered > 1e-4,
        "the rheological core keeps part of the dent"
    );
    assert!(
        layered < core_alone,
        "the viscoelastic skin pulls part of it back"
    );
}
