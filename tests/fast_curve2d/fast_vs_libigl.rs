//! gwn's fast (Barnes–Hut) evaluator at the documented β is at least as accurate as libigl's fast
//! winding number (`FastWindingNumberBVH`, order 2, accuracy_scale 2) on every mesh of the shared
//! corpus libigl reads: the max error against the direct sum, over the same points, may not exceed
//! libigl's. libigl's errors are constants measured once (libigl is not needed here), with
//!
//! ```text
//! benches/peers/run.sh --help >/dev/null 2>&1; # creates benches/peers/.venv with libigl 2.6.3
//! benches/peers/.venv/bin/python benches/peers/fast_accuracy.py ../shared/meshes --rust
//! ```
//!
//! (`fast_accuracy.py` documents the points: every `step`-th point of the 32³ grid of `gwn bench`,
//! the points within 1e-6·diagonal of the surface left out.)

use crate::common;

use gwn::Mesh;
use gwn::eval::direct::winding_number_direct_batch;
use gwn::eval::fast::{FastParams, FastWindingNumber};
use gwn::products::sdf::SignedDistance;

/// The β (Barill's rule, order 2) documented as at least as accurate as libigl's default
/// (docs/fast.md, docs/benchmarks.md "Fast (Barnes–Hut)").
const BETA: f64 = 2.8;
/// Triangle visits of the direct sum per mesh: the subset has `budget / faces` points (at least
/// 256, at most the grid), as in `fast_accuracy.py`.
const BUDGET: f64 = 1e7;

/// (mesh, faces, libigl's max error on the subset), from `fast_accuracy.py --rust`.
const LIBIGL_MAX_ERROR: &[(&str, usize, f64)] = &[
    ("assimp-3DSMaxExport.STL", 2000, 0.0013352295960996044),
    ("assimp-Spider_ascii.stl", 1368, 0.001690047959957276),
    ("assimp-Spider_binary.stl", 1368, 0.0017799915088187912),
    ("assimp-box.obj", 12, 3.7186585467486478e-06),
    ("assimp-box_longline.obj", 944, 5.0653546921353154e-05),
    ("assimp-concave_polygon.obj", 64, 9.631597006865e-05),
    ("assimp-empty_mat.obj", 256, 0.00569407321053228),
    ("assimp-float-color.ply", 1, 7.655788304639088e-06),
    ("assimp-multiple_spaces.obj", 1, 9.526835297313241e-07),
    ("assimp-regr01.obj", 2710, 0.0018663546153682093),
    ("assimp-sphereWithHole.stl", 285, 0.001417076737492362),
    ("assimp-spider.obj", 1368, 0.0018235378611966002),
    ("assimp-testmixed.obj", 12, 3.680713051359688e-06),
    (
        "assimp-triangle_with_two_solids.stl",
        2,
        4.575301376215021e-05,
    ),
    ("cgal-3torus.off", 46, 0.0005910485225523134),
    ("cgal-ALSTOM_TEST4.off", 2033, 0.002267607717849729),
    ("cgal-ChineseDragon-10kv.off", 19994, 0.0017781538028674628),
    ("cgal-anchor.off", 1050, 0.0061985413389878),
    ("cgal-armadillo.off", 52000, 0.0011367711508625637),
    ("cgal-b9_mesh.off", 10174, 0.0019835691431174807),
    ("cgal-blade.off", 16222, 0.006003537492812293),
    ("cgal-blobby_3cc.off", 3417, 0.0020484713005811672),
    ("cgal-bull.off", 12396, 0.0015054513627567245),
    ("cgal-bunny00.off", 75408, 0.0011888489716903382),
    ("cgal-camel.off", 19536, 0.0050279204346449415),
    ("cgal-cheese.off", 17786, 0.004337880969410346),
    ("cgal-corner_with_sharp_edge.off", 30, 0.001528435067893439),
    ("cgal-cow.off", 5804, 0.0026796628209126983),
    ("cgal-degtri_sliding.off", 8, 2.815754142562743e-05),
    ("cgal-diplodocus.off", 47960, 0.0007979771668755891),
    ("cgal-double-torus-example.off", 466, 0.0016835088211742746),
    ("cgal-eight.off", 634, 0.001917703675528014),
    ("cgal-ellipe0.003.off", 3108, 0.002362838170335335),
    ("cgal-fandisk.off", 12946, 0.0030298440882824407),
    ("cgal-fandisk_large.off", 31682, 0.003030451216208929),
    ("cgal-femur.off", 7798, 0.002221756818479137),
    ("cgal-fold.off", 12, 0.0012224540628129887),
    ("cgal-hand.off", 2390, 0.0022801169903874374),
    ("cgal-holes.off", 8288, 0.0016189268969957205),
    ("cgal-horizons.off", 3200, 0.0018120239975156771),
    ("cgal-knot1.off", 6400, 0.0026476089952692317),
    ("cgal-knot2.off", 11520, 0.0017481211450341982),
    ("cgal-lion-head.off", 16674, 0.0016536902763292227),
    ("cgal-man.off", 34986, 0.0020479664495977046),
    ("cgal-mannequin-devil.off", 25888, 0.0018056211572801129),
    ("cgal-mask_cone.off", 2332, 0.0016224735746489527),
    ("cgal-mech-holes-shark.off", 10192, 0.0021432783736036187),
    ("cgal-mesh_with_border.off", 1014, 0.00117918648955323),
    ("cgal-mpi.off", 180, 0.000993764696701871),
    ("cgal-nefertiti.off", 562, 0.0015464146315805616),
    ("cgal-patch-01.off", 1396, 0.002258538608864158),
    ("cgal-pig.stl", 16848, 0.0026569379868324194),
    ("cgal-rotor.off", 1200, 0.003950296824719975),
    ("cgal-tet-shuffled.off", 4, 1.7053887954032731e-06),
    (
        "cgal-tetra_intersected_by_triangle.off",
        5,
        5.345587067301567e-05,
    ),
    ("cgal-tetrahedron.off", 4, 2.0870022466224917e-06),
    ("cgal-three_peaks.off", 3671, 0.0022789657702509958),
    ("cgal-torus_quad.off", 50, 0.0010186355586476864),
    ("cgal-triangle.off", 1, 4.555182293308757e-06),
    ("cgal-triangular_hole.off", 6, 7.530453824231009e-05),
    ("cgal-triceratops.off", 5660, 0.0019463098358644007),
    ("cgal-tripod.off", 44, 0.001996426348899297),
    ("cgal-turbine.off", 18460, 0.0028196242264444966),
    (
        "cura-UltimakerRobot_support.stl",
        187974,
        0.00263191065624098,
    ),
    (
        "cura-anycubic_chiron_platform.obj",
        22,
        0.0004691086697405922,
    ),
    (
        "cura-anycubic_mega_zero_platform.stl",
        1304,
        0.001058513754483309,
    ),
    (
        "cura-arjunpro300_platform.STL",
        14216,
        0.0019034309814012003,
    ),
    ("cura-deltacomb_dc30.stl", 6066, 0.0013779921322374779),
    (
        "cura-eryone_thinker_platform.obj",
        6786,
        0.00282749832740198,
    ),
    ("cura-hellbot_hidra.obj", 236, 0.0012798737319341669),
    ("cura-kingroon_kp3.stl", 10164, 0.0032793736659603168),
    ("cura-lulzbot_taz_pro_bed.stl", 14320, 0.0011462376626143647),
    ("cura-mingda_d2_base.stl", 5404, 0.0006656398801131796),
    ("cura-predator_platform.stl", 8426, 0.001509881654350953),
    (
        "cura-twotrees235x235_generic.stl",
        316,
        0.0010064978371467463,
    ),
    ("cura-ultimaker2_platform.obj", 6192, 0.0004282658676684321),
    ("cura-ultimaker3_platform.obj", 20456, 0.0009263538925565779),
    ("cura-voron0_120_bed.stl", 13728, 0.0023023874001025344),
    ("npm-dragon_vrip_res2.ply", 202520, 0.0014609389250717017),
    ("npm-dragon_vrip_res3.ply", 47794, 0.0011114632841330895),
    ("npm-dragon_vrip_res4.ply", 11102, 0.002847657646959915),
    (
        "openscad-bad-stl-pcbvicebar.stl",
        260,
        0.0015136031223834227,
    ),
    ("openscad-import.stl", 46, 0.0008733013468162049),
    ("openscad-import_bin.stl", 46, 0.0008733013468161778),
    (
        "openscad-issue1580-back-to-back2.stl",
        14,
        0.0005133835798649296,
    ),
    (
        "openscad-issue1580-zero-area-triangle.stl",
        14,
        3.968150180302147e-05,
    ),
    ("openscad-issue945f.stl", 24, 0.0007169890288493651),
    ("prusa-A350_bed.stl", 240, 0.0004360280560118442),
    (
        "prusa-PLA_recycling_symbol.stl",
        1244,
        0.0017969347252230845,
    ),
    ("prusa-aqp_bed.stl", 17328, 0.00015167802053311764),
    ("prusa-bunny.stl", 292, 0.0014034520924560315),
    ("prusa-helper_disk.stl", 744, 0.0011618778027090214),
    ("prusa-sl1_bed.stl", 8320, 0.0014355658395226985),
    ("prusa-torus.stl", 3072, 0.002752973518004298),
    ("pymeshlab-airplane.obj", 10796, 0.0033879350966817454),
    ("pymeshlab-bunny.obj", 56172, 0.0009891252283039916),
    (
        "pymeshlab-bunny10k_textured.obj",
        9999,
        0.0022006563046140792,
    ),
    ("pyvista-ant.ply", 912, 0.0011520554778254816),
];

/// The grid of `gwn bench` in `peers.py`'s order (x fastest), same operations.
fn grid(mesh: &Mesh, n: usize) -> Vec<[f64; 3]> {
    let b = mesh.bounding_box().expect("non-empty mesh").enlarged(0.1);
    let mut out = Vec::with_capacity(n * n * n);
    for i in 0..n * n * n {
        let idx = [i % n, (i / n) % n, i / (n * n)];
        out.push(std::array::from_fn(|k| {
            b.min[k] + (b.max[k] - b.min[k]) * (idx[k] as f64 + 0.5) / n as f64
        }));
    }
    out
}

#[test]
fn fast_is_at_least_as_accurate_as_libigl_on_the_corpus() {
    let Some(dir) = common::shared_meshes() else {
        return;
    };
    assert!(LIBIGL_MAX_ERROR.len() >= 90, "the table covers the corpus");
    let mut worse = Vec::new();
    for &(name, faces, igl) in LIBIGL_MAX_ERROR {
        let mesh = gwn::io::load_mesh(dir.join(name))
            .expect("corpus mesh loads")
            .mesh;
        assert_eq!(
            mesh.triangles().len(),
            faces,
            "{name}: another file than measured"
        );
        let points = grid(&mesh, 32);
        let want = (BUDGET / faces as f64)
            .floor()
            .max(256.0)
            .min(points.len() as f64) as usize;
        let step = points.len().div_ceil(want).max(1);
        let fast = FastWindingNumber::with_params(&mesh, FastParams::barill(BETA, 2));
        let b = mesh.bounding_box().expect("non-empty");
        let diag = (0..3)
            .map(|k| (b.max[k] - b.min[k]).powi(2))
            .sum::<f64>()
            .sqrt();
        let distance = SignedDistance::with_evaluator(&mesh, fast.clone());
        let subset: Vec<[f64; 3]> = points
            .iter()
            .step_by(step)
            .copied()
            .filter(|&q| distance.unsigned(q) > 1e-6 * diag)
            .collect();
        let exact = winding_number_direct_batch(&mesh, &subset);
        let approx = fast.eval_batch(&subset);
        let err = approx
            .iter()
            .zip(&exact)
            .map(|(a, e)| (a - e).abs())
            .fold(0.0, f64::max);
        println!("{name}: gwn {err:.3e}, libigl {igl:.3e}");
        if err > igl {
            worse.push(format!("{name} ({err:.3e} > {igl:.3e})"));
        }
    }
    assert!(
        worse.is_empty(),
        "gwn fast at β = {BETA} is less accurate than libigl on {} meshes: {}",
        worse.len(),
        worse.join(", ")
    );
}
