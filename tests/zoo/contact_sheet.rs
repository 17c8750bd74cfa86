//! The contact sheet (`render` without `--technique`): its reference tiles, its numbers, and
//! the copy embedded in the README.

use std::path::PathBuf;
use std::sync::OnceLock;

use glam::UVec2;
use shadow_zoo::contact_sheet::{self, Layout, Sheet};
use zoo_host::Renderer;
use zoo_host::judging::DEFAULT_SAMPLES;
use zoo_host::test_support::{gpu, workspace_root};

/// Tile size of the README's contact sheet, which the long checks share (the README's copy
/// and GL's parity).
pub const README_TILE: UVec2 = UVec2::new(256, 192);
/// Tile size of the suite's sheet: a quarter of the README's pixels (the reference's area
/// samples, the exact and ray-traced techniques pay by the pixel).
const SUITE_TILE: UVec2 = UVec2::new(128, 96);
/// The README's contact sheet, relative to the workspace root.
const README_IMAGE: &str = "host/app/docs/contact-sheet.png";

/// The default scene's sheet at [`README_TILE`] on the test adapter, built once for every test
/// that reads it.
pub fn readme_sheet() -> &'static Sheet {
    static SHEET: OnceLock<Sheet> = OnceLock::new();
    SHEET.get_or_init(|| sheet(gpu(), README_TILE))
}

/// The default scene's sheet of every shipped technique available on `gpu`.
pub fn sheet(gpu: std::sync::Arc<zoo_host::GpuContext>, size: UVec2) -> Sheet {
    let scene = shadow_zoo::setup::load_scene(None).unwrap();
    let (available, _) = contact_sheet::available_techniques(&gpu);
    let techniques: Vec<_> = available
        .into_iter()
        .filter(|r| r.package != env!("CARGO_PKG_NAME"))
        .map(|r| (r, zoo_host::params::defaults(&(r.params)())))
        .collect();
    let mut renderer = Renderer::new(gpu, scene, size).unwrap();
    contact_sheet::build(&mut renderer, &techniques, DEFAULT_SAMPLES, |_| {}).unwrap()
}

/// Pixels within one pixel of a hard shadow boundary of any light of the default scene.
fn edge_band(size: UVec2) -> Vec<bool> {
    let scene = shadow_zoo::setup::load_scene(None).unwrap();
    let mut renderer = Renderer::new(gpu(), scene, size).unwrap();
    let reference = zoo_host::judging::SceneReference::compute(&mut renderer, 1, |_| {}).unwrap();
    let (w, h) = (size.x as i64, size.y as i64);
    (0..w * h)
        .map(|i| {
            let (x, y) = (i % w, i / w);
            reference.lights.iter().any(|l| {
                (-1..=1).any(|dy: i64| {
                    (-1..=1).any(|dx: i64| {
                        let (nx, ny) = (x + dx, y + dy);
                        (0..w).contains(&nx)
                            && (0..h).contains(&ny)
                            && l.hard[(ny * w + nx) as usize] != l.hard[i as usize]
                    })
                })
            })
        })
        .collect()
}

/// Fraction of pixels whose channels differ by more than `threshold`.
fn differing(a: &image::RgbaImage, b: &image::RgbaImage, threshold: u8) -> f64 {
    let count = a
        .pixels()
        .zip(b.pixels())
        .filter(|(p, q)| (0..3).any(|c| p[c].abs_diff(q[c]) > threshold))
        .count();
    count as f64 / a.pixels().len() as f64
}

#[test]
fn the_sheet_shows_every_technique_beside_a_reference_that_exact_techniques_match() {
    let sheet = &sheet(gpu(), SUITE_TILE);
    let ids: Vec<&str> = sheet.rows.iter().map(|r| r.id.as_str()).collect();
    assert_eq!(&ids[..2], ["reference (hard)", "reference (area)"]);
    for r in crate::shipped_techniques() {
        assert!(ids.contains(&r.id), "{} missing from {ids:?}", r.id);
    }
    let row = |id: &str| sheet.rows.iter().position(|r| r.id == id).unwrap();

    // Shadow volumes are exact: their frame, shaded on the GPU, matches the hard reference
    // shaded on the CPU except in the one-pixel band along the reference's shadow edges.
    let hard = &sheet.images[0];
    let volumes = &sheet.images[row("sv-zfail")];
    let band = edge_band(SUITE_TILE);
    let off_edges = hard
        .pixels()
        .zip(volumes.pixels())
        .zip(&band)
        .filter(|((p, q), on_edge)| !**on_edge && (0..3).any(|c| p[c].abs_diff(q[c]) > 6))
        .count() as f64
        / band.len() as f64;
    assert!(
        off_edges < 0.002,
        "sv-zfail differs from the hard reference away from shadow edges in {off_edges} of the pixels"
    );
    // The reference does show shadows: unshadowed differs from it.
    let unshadowed = &sheet.images[row("unshadowed")];
    let shadowed = differing(hard, unshadowed, 6);
    assert!(shadowed > 0.05, "only {shadowed} of the pixels shadowed");

    let u = sheet.rows[row("unshadowed")].summary.unwrap();
    assert_eq!(u.false_shadow_core, 0.0);
    // Measured 0.0136 at 96x64 tiles; larger tiles keep it above 0.01 (the core excludes a
    // band along every edge, one pixel wide at any tile size).
    assert!(u.false_lit_core > 0.01, "{u:?}");
    let sv = sheet.rows[row("sv-zfail")].summary.unwrap();
    assert!(sv.false_shadow_core + sv.false_lit_core <= 0.002, "{sv:?}");
    assert!(sheet.rows[row("sm-pcf")].frame_ms.unwrap() > 0.0);

    let table = contact_sheet::table(sheet);
    for id in &ids {
        assert!(table.contains(id), "{id} missing from\n{table}");
    }
    let image = contact_sheet::draw(sheet).unwrap();
    let layout = Layout::new((SUITE_TILE.x, SUITE_TILE.y), sheet.images.len());
    assert_eq!(image.dimensions(), layout.size());
}

/// The README embeds the sheet of the first command (at [`README_TILE`]). Its tiles must
/// show what the current code renders; set `UPDATE_README_IMAGES=1` to regenerate it.
#[test]
#[ignore = "long check: `bash tests/run.sh --long` (CI runs it after the suite)"]
fn the_readme_contact_sheet_is_up_to_date() {
    let path: PathBuf = workspace_root().join(README_IMAGE);
    let readme = std::fs::read_to_string(workspace_root().join("README.md")).unwrap();
    assert!(
        readme.contains(&format!("]({README_IMAGE})")),
        "README.md must embed {README_IMAGE}"
    );
    let sheet = readme_sheet();
    let fresh = contact_sheet::draw(sheet).unwrap();
    if std::env::var_os("UPDATE_README_IMAGES").is_some() {
        std::fs::create_dir_all(path.parent().unwrap()).unwrap();
        fresh.save(&path).unwrap();
        eprintln!("wrote {}", path.display());
        return;
    }
    let regenerate = "regenerate it with `UPDATE_README_IMAGES=1 bash tests/run.sh --test zoo \
                      contact_sheet -- --ignored`";
    let committed = image::open(&path)
        .unwrap_or_else(|e| panic!("{}: {e}; {regenerate}", path.display()))
        .to_rgba8();
    assert_eq!(
        committed.dimensions(),
        fresh.dimensions(),
        "{README_IMAGE} has another layout (techniques added or removed?); {regenerate}"
    );
    // Only the tiles are compared: labels hold frame times, which vary from run to run.
    let layout = Layout::new((README_TILE.x, README_TILE.y), sheet.images.len());
    let fresh = image::DynamicImage::ImageRgb8(fresh).to_rgba8();
    for (i, row) in sheet.rows.iter().enumerate() {
        let (x, y) = layout.origin(i);
        let crop = |img: &image::RgbaImage| {
            image::imageops::crop_imm(img, x, y, README_TILE.x, README_TILE.y).to_image()
        };
        let off = differing(&crop(&committed), &crop(&fresh), 24);
        assert!(
            off < 0.01,
            "tile {i} ({}) of {README_IMAGE} differs in {:.2}% of its pixels; {regenerate}",
            row.id,
            off * 100.0
        );
    }
}
