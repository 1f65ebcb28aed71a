//! The form-factor methods measured against closed forms: error against cost, point by point (the
//! cases of `docs/closed-forms.md`, "A point and a polygon", "Rectangles by superposition" and "The
//! textbook scene"), the hemicube's aliasing on patches about a pixel in size, the face-to-face
//! factors of the 1 × 2 × 3 box ("The 1 × 2 × 3 box"), and whole solutions of the unit cube with
//! one emitting face ("The unit cube with one emitting face"), solved densely so that the form
//! factors are the only approximation besides the mesh.

use std::time::Instant;

use glam::DVec3;
use penumbra_meshing::{SceneMesh, mesh_scene_uniform};
use penumbra_scenes::{Rgb, Scene, Surface, SurfaceId, Visibility, builtin};
use penumbra_solver::OptionId;
use penumbra_solver::coupling::{Coupler, FormFactorMethod, PatchCoupling, hemicube_row};
use penumbra_solver::hemicube::Hemicube;
use penumbra_solver::{
    Discretization, NoProgress, ReceivingPoint, SolveError, SolverMethod, SolverOptions,
    solve_gathering,
};
use serde::Serialize;

/// Which configurations to measure.
#[derive(Clone, Debug)]
pub struct StudyOptions {
    /// Rays per point–patch pair for the analytic method's visibility fraction.
    pub rays: usize,
    /// Monte Carlo sample counts.
    pub samples: Vec<usize>,
    /// Hemicube resolutions.
    pub resolutions: Vec<usize>,
    /// Independent random streams over which the stochastic methods' errors are averaged.
    pub streams: usize,
    /// Triangles of the unit cube's mesh in the whole-solution comparison.
    pub cube_elements: usize,
}

impl Default for StudyOptions {
    fn default() -> Self {
        StudyOptions {
            rays: SolverOptions::default().visibility_rays,
            samples: vec![64, 256, 4096],
            resolutions: vec![32, 64, 128, 256, 512],
            streams: 16,
            cube_elements: 2400,
        }
    }
}

/// Most random streams a study averages over: beyond this the tables do not change in their
/// printed digits, and a run only looks hung.
pub const MAX_STREAMS: usize = 1024;

/// Most triangles of the unit cube's mesh: its dense solve holds a matrix of their vertices'
/// square.
pub const MAX_CUBE_ELEMENTS: usize = 20_000;

impl StudyOptions {
    /// Checks every option's range before anything is measured; names as
    /// [`crate::RunOptions::validate`] gives them.
    pub fn validate(&self) -> Result<(), crate::InvalidOption> {
        let bad = |option, reason: String| Err(crate::InvalidOption { option, reason });
        if !(1..=MAX_STREAMS).contains(&self.streams) {
            return bad(
                OptionId::Streams,
                format!("must be from 1 to {MAX_STREAMS}, not {}", self.streams),
            );
        }
        if !(12..=MAX_CUBE_ELEMENTS).contains(&self.cube_elements) {
            return bad(
                OptionId::CubeElements,
                format!(
                    "must be from 12 (two per face) to {MAX_CUBE_ELEMENTS}, not {}",
                    self.cube_elements
                ),
            );
        }
        for c in MethodConfig::all(self) {
            SolverOptions {
                form_factors: c.method,
                visibility_rays: self.rays,
                ..SolverOptions::default()
            }
            .validate()?;
        }
        Ok(())
    }
}

/// One method with its setting, and how it is named in the tables.
#[derive(Clone, Copy, Debug, Serialize)]
pub struct MethodConfig {
    /// The method and what its setting is, as the tables name them (`hemicube (resolution)`).
    pub label: &'static str,
    /// The setting: rays per pair, samples, or the hemicube's resolution in pixels.
    pub setting: usize,
    /// The method and its setting, as the solver takes them.
    #[serde(skip)]
    pub method: FormFactorMethod,
}

impl MethodConfig {
    fn all(options: &StudyOptions) -> Vec<MethodConfig> {
        let mut all = vec![MethodConfig {
            label: "analytic (rays)",
            setting: options.rays,
            method: FormFactorMethod::Analytic,
        }];
        all.extend(options.samples.iter().map(|&samples| MethodConfig {
            label: "monte-carlo (samples)",
            setting: samples,
            method: FormFactorMethod::MonteCarlo { samples },
        }));
        all.extend(options.resolutions.iter().map(|&resolution| MethodConfig {
            label: "hemicube (resolution)",
            setting: resolution,
            method: FormFactorMethod::Hemicube { resolution },
        }));
        all
    }

    fn stochastic(&self) -> bool {
        !matches!(self.method, FormFactorMethod::Hemicube { .. })
    }
}

/// A point-to-polygon case with a closed-form answer.
#[derive(Clone, Debug, Serialize)]
pub struct PointCase {
    /// What the case is, in words.
    pub name: &'static str,
    /// Where the closed form comes from (its case in `docs/closed-forms.md`).
    pub source: &'static str,
    /// The point-to-polygon form factor, from the closed form.
    pub exact: f64,
}

/// One method's error on every point case, and its cost.
#[derive(Clone, Debug, Serialize)]
pub struct PointRow {
    /// The method and its setting.
    pub config: MethodConfig,
    /// Relative error per case, in the order of the cases (RMS over the random streams for
    /// stochastic methods).
    pub errors: Vec<f64>,
    /// Mean time of one evaluation, in microseconds (for the hemicube: one hemicube, which gives
    /// the point's form factor to every patch at once).
    pub micros: f64,
}

/// The hemicube's (and Monte Carlo's) answer for a small square as it slides by fractions of a
/// pixel: the range of computed / exact.
#[derive(Clone, Debug, Serialize)]
pub struct AliasingRow {
    /// The method and its setting.
    pub config: MethodConfig,
    /// The square's side, in pixels of the hemicube at `pixels_of` resolution.
    pub pixels: f64,
    /// The hemicube resolution `pixels` is measured in (the study's middle one), also for
    /// Monte Carlo.
    pub pixels_of: usize,
    /// The exact form factor, averaged over the square's positions.
    pub exact: f64,
    /// The least of computed / exact over the positions.
    pub min_ratio: f64,
    /// The most of computed / exact over the positions.
    pub max_ratio: f64,
}

/// The 1 × 2 × 3 box's face-to-face factors from the discrete system.
#[derive(Clone, Debug, Serialize)]
pub struct BoxRow {
    /// The method and its setting.
    pub config: MethodConfig,
    /// Worst relative error of the 30 face pairs against the closed forms.
    pub worst_error: f64,
    /// Worst |row sum − 1|: the box is closed, so each face's factors sum to 1.
    pub worst_row_sum: f64,
    /// Seconds of the form factors.
    pub seconds: f64,
}

/// The unit cube with one emitting face, solved densely.
#[derive(Clone, Debug, Serialize)]
pub struct CubeRow {
    /// The method and its setting.
    pub config: MethodConfig,
    /// Triangles of the cube's mesh.
    pub triangles: usize,
    /// Face-mean radiosities: the emitter, the mean of the four adjacent faces, the opposite.
    pub faces: [f64; 3],
    /// Their relative errors against the continuous limit (`docs/closed-forms.md`, "The unit cube
    /// with one emitting face").
    pub errors: [f64; 3],
    /// Seconds of the form factors and the solve.
    pub seconds: f64,
}

/// The whole study (`form-factors.json`); [`Study::markdown`] prints it as tables.
#[derive(Clone, Debug, Serialize)]
pub struct Study {
    /// The point-to-polygon cases, with their closed-form values.
    pub cases: Vec<PointCase>,
    /// Per method and setting, the error on each case and the cost.
    pub points: Vec<PointRow>,
    /// The hemicube's and Monte Carlo's ranges on small sliding squares.
    pub aliasing: Vec<AliasingRow>,
    /// Per method and setting, the 1 × 2 × 3 box's face-to-face factors.
    pub box_factors: Vec<BoxRow>,
    /// The unit cube's reflectance, every face (0.9).
    pub cube_reflectance: f64,
    /// The continuous limit of the unit cube's face means (emitter, adjacent, opposite), in
    /// W/m² for an emitting face of exitance 1 W/m².
    pub cube_reference: [f64; 3],
    /// Per method and setting, the unit cube's face means and their errors.
    pub cube: Vec<CubeRow>,
}

/// A point of the `receiver` surface, and the `target` surface it looks at.
#[derive(Clone, Copy, Debug)]
struct Probe {
    point: DVec3,
    receiver: SurfaceId,
    target: SurfaceId,
}

/// A scene prepared for point evaluations: one patch per surface.
struct Setup {
    scene: Scene,
    visibility: Visibility,
    disc: Discretization,
}

impl Setup {
    fn new(scene: Scene) -> Result<Setup, StudyError> {
        let visibility = Visibility::build(&scene);
        let mesh = mesh_scene_uniform(&scene, 40 * scene.surfaces.len())?;
        let disc = Discretization::new(&scene, &mesh, usize::MAX / 2);
        Ok(Setup {
            scene,
            visibility,
            disc,
        })
    }

    fn patch_of(&self, surface: SurfaceId) -> usize {
        self.disc
            .patches
            .iter()
            .position(|p| p.surface == surface)
            .unwrap_or(0)
    }

    /// The form factor of `probe` by `method`; `stream` picks the random stream.
    fn evaluate(
        &self,
        cube: Option<&mut Hemicube>,
        method: FormFactorMethod,
        rays: usize,
        probe: Probe,
        stream: u64,
    ) -> f64 {
        let Probe {
            point,
            receiver,
            target,
        } = probe;
        let normal = self.scene.surfaces[receiver].normal();
        let x = ReceivingPoint::interior(point, normal);
        let patch = self.patch_of(target);
        match cube {
            Some(cube) => {
                let mut row = vec![0.0; self.disc.patches.len()];
                hemicube_row(cube, &self.disc, &self.visibility, &x, receiver, &mut row);
                row[patch]
            }
            None => {
                let coupler = Coupler {
                    visibility: &self.visibility,
                    rays,
                    seed: 0x5EED,
                    method,
                };
                coupler
                    .coupling(&x, receiver, &self.disc.patches[patch], [stream, 0])
                    .0
            }
        }
    }
}

/// Errors of the study (its scenes are built in, so these mean a bad option).
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum StudyError {
    /// An option of the study out of its range ([`StudyOptions::validate`]).
    #[error(transparent)]
    InvalidOption(#[from] crate::InvalidOption),
    /// The solver failed, or refused a method's setting.
    #[error(transparent)]
    Solve(#[from] SolveError),
    /// A mesh of the study's scenes that could not be made.
    #[error(transparent)]
    Mesh(#[from] penumbra_meshing::MeshError),
}

fn v(x: f64, y: f64, z: f64) -> DVec3 {
    DVec3::new(x, y, z)
}

/// An axis-aligned rectangle in the plane `axis = at`, spanning `lo..hi` in the other two axes
/// (in the order x, y, z less `axis`), facing `toward`.
fn rectangle(
    name: &str,
    axis: usize,
    at: f64,
    lo: [f64; 2],
    hi: [f64; 2],
    toward: DVec3,
) -> Surface {
    let point = |a: f64, b: f64| {
        let mut p = [0.0; 3];
        let others: Vec<usize> = (0..3).filter(|&k| k != axis).collect();
        p[axis] = at;
        p[others[0]] = a;
        p[others[1]] = b;
        DVec3::from_array(p)
    };
    let mut polygon = vec![
        point(lo[0], lo[1]),
        point(hi[0], lo[1]),
        point(hi[0], hi[1]),
        point(lo[0], hi[1]),
    ];
    let n = (polygon[1] - polygon[0]).cross(polygon[2] - polygon[0]);
    if n.dot(toward - polygon[0]) < 0.0 {
        polygon.reverse();
    }
    Surface::new(name, polygon, Rgb::splat(0.5))
}

/// A receiver square of half-side `half` about the origin, facing +z, and one target.
fn point_scene(target: Surface, half: f64) -> Scene {
    Scene {
        up: None,
        unit: None,
        name: "form factor".into(),
        camera: None,
        surfaces: vec![
            rectangle(
                "receiver",
                2,
                0.0,
                [-half, -half],
                [half, half],
                v(0.0, 0.0, 1.0),
            ),
            target,
        ],
    }
}

/// The origin of [`point_scene`]'s receiver, looking at its target.
const AT_ORIGIN: Probe = Probe {
    point: DVec3::ZERO,
    receiver: 0,
    target: 1,
};

/// The point cases: scene, probe, and the case.
fn point_cases() -> Vec<(Scene, Probe, PointCase)> {
    let origin = DVec3::ZERO;
    let textbook = builtin::textbook();
    let (floor, light) = (
        textbook.surface_id("floor").unwrap_or(2),
        textbook.surface_id("light").unwrap_or(0),
    );
    let on_floor = |x: f64| Probe {
        point: v(x, 0.0, 0.0),
        receiver: floor,
        target: light,
    };
    vec![
        (
            point_scene(
                rectangle("target", 2, 1.0, [0.0, 0.0], [1.0, 1.0], origin),
                0.1,
            ),
            AT_ORIGIN,
            PointCase {
                name: "parallel square, corner on the normal",
                source: "1.1, a = b = c = 1",
                exact: 0.138531605994893,
            },
        ),
        (
            point_scene(
                rectangle("target", 2, 2.0, [0.0, 0.0], [0.5, 0.25], origin),
                0.1,
            ),
            AT_ORIGIN,
            PointCase {
                name: "small distant rectangle",
                source: "1.1, a = 0.5, b = 0.25, c = 2",
                exact: 0.00945845765854797,
            },
        ),
        (
            point_scene(
                rectangle("target", 0, 1.0, [0.0, 0.0], [1.0, 1.0], origin),
                0.1,
            ),
            AT_ORIGIN,
            PointCase {
                name: "perpendicular square",
                source: "1.2, a = b = c = 1",
                exact: 0.0557341970025535,
            },
        ),
        (
            point_scene(
                rectangle("target", 0, 1.0, [-1.0, -1.0], [1.0, 1.0], origin),
                0.1,
            ),
            AT_ORIGIN,
            PointCase {
                name: "square straddling the tangent plane",
                source: "1.6 D",
                exact: 0.111468394005107,
            },
        ),
        (
            textbook.clone(),
            on_floor(0.75),
            PointCase {
                name: "light through a blocker, penumbra x = 0.75",
                source: "3.2",
                exact: 0.0163850596402602,
            },
        ),
        (
            textbook,
            on_floor(0.6),
            PointCase {
                name: "light through a blocker, penumbra x = 0.6",
                source: "3.2",
                exact: 0.00688007281804919,
            },
        ),
    ]
}

/// Runs the whole study: every method and setting of `options` on the point cases, the
/// aliasing squares, the 1 × 2 × 3 box and the unit cube.
pub fn run_study(options: &StudyOptions) -> Result<Study, StudyError> {
    options.validate()?;
    let configs = MethodConfig::all(options);
    let streams = options.streams;
    let cases = point_cases();
    let setups = cases
        .iter()
        .map(|c| Setup::new(c.0.clone()))
        .collect::<Result<Vec<_>, _>>()?;

    let mut points = Vec::new();
    for config in &configs {
        let mut cube = match config.method {
            FormFactorMethod::Hemicube { resolution } => Some(Hemicube::new(resolution)?),
            _ => None,
        };
        let mut errors = Vec::new();
        let started = Instant::now();
        let mut evaluations = 0usize;
        for ((_, probe, case), setup) in cases.iter().zip(&setups) {
            let mut sum2 = 0.0;
            for stream in 0..streams {
                let f = setup.evaluate(
                    cube.as_mut(),
                    config.method,
                    options.rays,
                    *probe,
                    stream as u64,
                );
                sum2 += ((f - case.exact) / case.exact).powi(2);
                evaluations += 1;
            }
            errors.push((sum2 / streams as f64).sqrt());
        }
        points.push(PointRow {
            config: *config,
            errors,
            micros: started.elapsed().as_secs_f64() * 1e6 / evaluations as f64,
        });
    }

    let aliasing = aliasing(options, streams)?;
    let box_factors = configs
        .iter()
        .map(|c| box_factors(c, options.rays))
        .collect::<Result<Vec<_>, _>>()?;
    let cube = configs
        .iter()
        .map(|c| cube_solution(c, options))
        .collect::<Result<Vec<_>, _>>()?;
    Ok(Study {
        cases: cases.into_iter().map(|c| c.2).collect(),
        points,
        aliasing,
        box_factors,
        cube_reflectance: CUBE_RHO,
        cube_reference: CUBE_LIMIT,
        cube,
    })
}

/// A square of side `side` centred at (`dx`, `dy`) at height 1 over the origin.
fn small_square(side: f64, dx: f64, dy: f64) -> Scene {
    let h = side / 2.0;
    point_scene(
        rectangle(
            "target",
            2,
            1.0,
            [dx - h, dy - h],
            [dx + h, dy + h],
            DVec3::ZERO,
        ),
        0.1,
    )
}

/// Sides of the aliasing test's squares, in hemicube pixels: between whole numbers, so that the
/// count of pixel centres a square covers changes as it slides.
pub const ALIASING_SIDES: [f64; 6] = [0.3, 0.7, 1.5, 2.5, 4.5, 16.5];

/// The hemicube at the middle resolution of the study, and Monte Carlo at its middle sample
/// count, on squares of 0.3 to 16.5 hemicube pixels sliding over 16 sub-pixel offsets.
fn aliasing(options: &StudyOptions, streams: usize) -> Result<Vec<AliasingRow>, StudyError> {
    let mid = |v: &[usize]| v.get(v.len() / 2).copied();
    let mut rows = Vec::new();
    let Some(resolution) = mid(&options.resolutions) else {
        return Ok(rows);
    };
    let pixel = 2.0 / resolution as f64; // at height 1, over the top face's centre
    let mut configs = vec![MethodConfig {
        label: "hemicube (resolution)",
        setting: resolution,
        method: FormFactorMethod::Hemicube { resolution },
    }];
    if let Some(samples) = mid(&options.samples) {
        configs.push(MethodConfig {
            label: "monte-carlo (samples)",
            setting: samples,
            method: FormFactorMethod::MonteCarlo { samples },
        });
    }
    for config in configs {
        let mut cube = match config.method {
            FormFactorMethod::Hemicube { resolution } => Some(Hemicube::new(resolution)?),
            _ => None,
        };
        for pixels in ALIASING_SIDES {
            let side = pixels * pixel;
            let (mut lo, mut hi, mut exact_mean) = (f64::INFINITY, f64::NEG_INFINITY, 0.0);
            for k in 0..16 {
                // Off the axis (the square sits over a generic spot of the top face), slid by
                // sixteenths of a pixel in x and sevenths in y.
                let (dx, dy) = (
                    0.3 + pixel * k as f64 / 16.0,
                    0.2 + pixel * (k % 7) as f64 / 7.0,
                );
                let setup = Setup::new(small_square(side, dx, dy))?;
                let exact = setup.evaluate(None, FormFactorMethod::Analytic, 1, AT_ORIGIN, 0);
                let stream = if config.stochastic() { k % streams } else { 0 };
                let f = setup.evaluate(
                    cube.as_mut(),
                    config.method,
                    options.rays,
                    AT_ORIGIN,
                    stream as u64,
                );
                lo = lo.min(f / exact);
                hi = hi.max(f / exact);
                exact_mean += exact / 16.0;
            }
            rows.push(AliasingRow {
                config,
                pixels,
                pixels_of: resolution,
                exact: exact_mean,
                min_ratio: lo,
                max_ratio: hi,
            });
        }
    }
    Ok(rows)
}

/// Face-to-face factors of the 1 × 2 × 3 box (one patch per face, 600 triangles), as the
/// solvers use them: area means of the vertex form factors.
fn box_factors(config: &MethodConfig, rays: usize) -> Result<BoxRow, StudyError> {
    let scene = builtin::closed_box(DVec3::new(1.0, 2.0, 3.0), 1.0, 0.5);
    let visibility = Visibility::build(&scene);
    let mesh = mesh_scene_uniform(&scene, 600)?;
    let disc = Discretization::new(&scene, &mesh, usize::MAX / 2);
    let started = Instant::now();
    let (columns, _) = PatchCoupling {
        disc: &disc,
        visibility: &visibility,
        rays,
        seed: 3,
        method: config.method,
        interrupt: None,
    }
    .columns(&NoProgress)?;
    let f = disc.patch_factors(&columns);
    let seconds = started.elapsed().as_secs_f64();
    let (mut worst_error, mut worst_row_sum) = (0.0f64, 0.0f64);
    for (i, row) in f.iter().enumerate() {
        worst_row_sum = worst_row_sum.max((row.iter().sum::<f64>() - 1.0).abs());
        for (j, &fij) in row.iter().enumerate() {
            let (si, sj) = (disc.patches[i].surface, disc.patches[j].surface);
            if si != sj {
                let exact = box_closed_form(&scene, si, sj);
                worst_error = worst_error.max((fij - exact).abs() / exact);
            }
        }
    }
    Ok(BoxRow {
        config: *config,
        worst_error,
        worst_row_sum,
        seconds,
    })
}

/// `docs/closed-forms.md`, "The 1 × 2 × 3 box": the closed-form factor from face `i` to face `j` of
/// the 1 × 2 × 3 box, told apart by the faces' side lengths.
fn box_closed_form(scene: &Scene, i: usize, j: usize) -> f64 {
    let sides = |s: usize| {
        let b = scene.surfaces[s].bounds();
        let d = b.max - b.min;
        let mut v = [d.x, d.y, d.z];
        v.sort_by(f64::total_cmp);
        (v[1], v[2])
    };
    let (face, other) = (sides(i), sides(j));
    let opposite = scene.surfaces[i].normal().dot(scene.surfaces[j].normal()) < -0.5;
    let is = |x: f64, y: f64| (x - y).abs() < 1e-9;
    if opposite {
        return if is(face.0, 2.0) {
            0.475576436532953
        } else if is(face.0, 1.0) && is(face.1, 3.0) {
            0.146414577931196
        } else {
            0.0603313853699537
        };
    }
    let shared = if is(face.0, other.0) || is(face.0, other.1) {
        face.0
    } else {
        face.1
    };
    match (face, shared) {
        ((a, _), s) if is(a, 2.0) && is(s, 2.0) => 0.102713430993999,
        ((a, _), _) if is(a, 2.0) => 0.159498350739525,
        ((_, b), s) if is(b, 3.0) && is(s, 1.0) => 0.107796009555352,
        ((_, b), _) if is(b, 3.0) => 0.31899670147905,
        (_, s) if is(s, 1.0) => 0.161694014333028,
        _ => 0.308140292981996,
    }
}

/// Reflectance of the unit cube in the whole-solution comparison.
const CUBE_RHO: f64 = 0.9;
/// `docs/closed-forms.md`, "The unit cube with one emitting face", at ρ = 0.9: the continuous limit
/// of the face means (emitter, adjacent, opposite), an Aitken estimate good to 4–5 digits.
const CUBE_LIMIT: [f64; 3] = [2.41938, 1.52318, 1.48788];

/// The unit cube with its floor emitting (E = 1) and every face reflecting 0.9, meshed uniformly
/// and solved densely with the method's form factors.
fn cube_solution(config: &MethodConfig, options: &StudyOptions) -> Result<CubeRow, StudyError> {
    let mut scene = builtin::closed_box(DVec3::ONE, 0.0, CUBE_RHO);
    let emitter = scene.surface_id("floor").unwrap_or(0);
    scene.surfaces[emitter].emission = Rgb::splat(1.0);
    let visibility = Visibility::build(&scene);
    let mesh = mesh_scene_uniform(&scene, options.cube_elements)?;
    let solver = SolverOptions {
        form_factors: config.method,
        visibility_rays: options.rays,
        ..SolverOptions::default()
    };
    let started = Instant::now();
    let solution = solve_gathering(
        &scene,
        &mesh,
        &visibility,
        &solver,
        SolverMethod::Direct,
        &NoProgress,
    )?;
    let seconds = started.elapsed().as_secs_f64();
    let means = face_means(&mesh, &solution.radiosity);
    let emitter_normal = scene.surfaces[emitter].normal();
    let (mut adjacent, mut opposite) = (0.0, 0.0);
    for (s, surface) in scene.surfaces.iter().enumerate() {
        let d = surface.normal().dot(emitter_normal);
        if d < -0.5 {
            opposite = means[s];
        } else if d.abs() < 0.5 {
            adjacent += means[s] / 4.0;
        }
    }
    let faces = [means[emitter], adjacent, opposite];
    Ok(CubeRow {
        config: *config,
        triangles: mesh.triangle_count(),
        faces,
        errors: std::array::from_fn(|k| (faces[k] - CUBE_LIMIT[k]) / CUBE_LIMIT[k]),
        seconds,
    })
}

/// Area means of the (grey) radiosity over each surface, linear over each triangle.
fn face_means(mesh: &SceneMesh, radiosity: &[Vec<Rgb>]) -> Vec<f64> {
    mesh.surfaces
        .iter()
        .map(|m| {
            let (mut sum, mut area) = (0.0, 0.0);
            for t in 0..m.triangles.len() {
                let [a, b, c] = m.triangle_points3(t);
                let at = 0.5 * (b - a).cross(c - a).length();
                let mean: f64 = m.triangles[t]
                    .iter()
                    .map(|&i| radiosity[m.surface][i as usize].mean())
                    .sum::<f64>()
                    / 3.0;
                sum += at * mean;
                area += at;
            }
            if area > 0.0 { sum / area } else { 0.0 }
        })
        .collect()
}

impl Study {
    /// The study as Markdown tables.
    pub fn markdown(&self) -> String {
        let mut out = String::new();
        let pct = |e: f64| format!("{:.3} %", 100.0 * e);
        out.push_str("Point to polygon: relative error (RMS over random streams), and time per evaluation\n\n| method | setting |");
        for c in &self.cases {
            out.push_str(&format!(" {} ({}) |", c.name, c.source));
        }
        out.push_str(" µs per evaluation |\n|---|---|");
        out.push_str(&"---|".repeat(self.cases.len() + 1));
        out.push('\n');
        for r in &self.points {
            out.push_str(&format!("| {} | {} |", r.config.label, r.config.setting));
            for &e in &r.errors {
                out.push_str(&format!(" {} |", pct(e)));
            }
            out.push_str(&format!(" {:.1} |\n", r.micros));
        }
        out.push_str("\nAliasing: a square of n pixels' side sliding over 16 sub-pixel offsets, computed / exact\n\n| method | setting | side (pixels) | exact F | min | max |\n|---|---|---|---|---|---|\n");
        for r in &self.aliasing {
            out.push_str(&format!(
                "| {} | {} | {} | {:.3e} | {:.3} | {:.3} |\n",
                r.config.label, r.config.setting, r.pixels, r.exact, r.min_ratio, r.max_ratio
            ));
        }
        out.push_str("\n1 × 2 × 3 box, 600 triangles, one patch per face: face-to-face factors\n\n| method | setting | worst error | worst row sum − 1 | seconds |\n|---|---|---|---|---|\n");
        for r in &self.box_factors {
            out.push_str(&format!(
                "| {} | {} | {} | {:.2e} | {:.3} |\n",
                r.config.label,
                r.config.setting,
                pct(r.worst_error),
                r.worst_row_sum,
                r.seconds
            ));
        }
        out.push_str(&format!(
            "\nUnit cube, floor emitting, ρ = {}: face means against the continuous limit ({:?}), dense solve\n\n| method | setting | triangles | emitter | adjacent | opposite | seconds |\n|---|---|---|---|---|---|---|\n",
            self.cube_reflectance, self.cube_reference
        ));
        for r in &self.cube {
            out.push_str(&format!(
                "| {} | {} | {} | {:+.3} % | {:+.3} % | {:+.3} % | {:.2} |\n",
                r.config.label,
                r.config.setting,
                r.triangles,
                100.0 * r.errors[0],
                100.0 * r.errors[1],
                100.0 * r.errors[2],
                r.seconds
            ));
        }
        out
    }
}
