//! Timing runs on synthetic IMU-like data (see `benches/synth.rs`), too long for criterion.
//!
//! ```text
//! cargo run --release -p ridi-regress --example svr_timing -- <task> <n> [options]
//!   tasks: svr | svc | grid | cascade | query | export <dir>
//!          | load-query <path>
//!   options: --c C --eps E --placements K --mem-mb M --never-precompute
//!            --save <path> (grid, cascade, query: save the trained model)
//!            --storage half|projected (grid, cascade, query; default projected)
//!            --queries Q (load-query: held-out queries, default 2000)
//!            --solver exact|nystrom --landmarks M --seed S (grid, cascade, query; default
//!            exact, 2048 landmarks, seed 0)
//! ```
//! `query <n> --save <path>` trains the cascade with fixed `C`/epsilon (no grid) and saves it;
//! `load-query <n> <path>` loads it and times prediction on one core and batched, on the
//! held-out sequences generated after the `n` training rows.
//! `RAYON_NUM_THREADS=1` gives one-core numbers. Peak memory is the process's VmHWM.

#[path = "../benches/synth.rs"]
mod synth;
#[path = "common/timing.rs"]
mod timing;

use timing::{peak_mb, thread_cpu_s, time_one};

use std::time::Instant;

use ridi_features::FeatureConfig;
use ridi_features::FeatureMatrixRef;
use ridi_regress::{
    Cascade, CascadeParams, GridSpec, Nystrom, Precompute, ProgressEvent, RegressorChoice, Solver,
    SolverConfig, Storage, Svc, SvcParams, Svr, SvrParams, TrainingSet,
};

fn arg<T: std::str::FromStr>(args: &[String], name: &str, default: T) -> T {
    args.iter()
        .position(|a| a == name)
        .and_then(|i| args.get(i + 1)?.parse().ok())
        .unwrap_or(default)
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let task = args.first().cloned().unwrap_or_else(|| "svr".into());
    let n: usize = args.get(1).and_then(|s| s.parse().ok()).unwrap_or(2000);
    let c: f64 = arg(&args, "--c", 10.0);
    let eps: f64 = arg(&args, "--eps", 0.01);
    let k: usize = arg(&args, "--placements", 4);
    let mem_mb: u64 = arg(&args, "--mem-mb", 2048);
    let mut solver_config = SolverConfig {
        kernel_memory: mem_mb << 20,
        ..SolverConfig::default()
    };
    if args.iter().any(|a| a == "--never-precompute") {
        solver_config.regressor_kernel = Precompute::Never;
    }
    if args.iter().any(|a| a == "--precompute-classifier") {
        solver_config.classifier_kernel = Precompute::Auto;
    }
    if let Some(i) = args.iter().position(|a| a == "--max-iter") {
        solver_config.smo.max_iter = args.get(i + 1).and_then(|v| v.parse().ok());
    }
    if task == "load-query" {
        return load_query(&args, n, k);
    }
    let t = Instant::now();
    let data = synth::generate(n, k, 150, 42);
    let x = FeatureMatrixRef::new(&data.x, data.dim)?;
    eprintln!("generated {n} x {} in {:.2?}", data.dim, t.elapsed());
    let gamma = 1.0 / data.dim as f32;
    let threads = rayon::current_num_threads();
    match task.as_str() {
        "svr" => {
            let y: Vec<f64> = data.y.iter().map(|v| v[1]).collect();
            let p = SvrParams {
                c,
                epsilon: eps,
                gamma,
                solver_config,
            };
            let t = Instant::now();
            let m = Svr::fit(x, &y, &p)?;
            let fit = t.elapsed();
            let pred = m.predict(x)?;
            let mse = pred
                .iter()
                .zip(&y)
                .map(|(a, b)| (a - b).powi(2))
                .sum::<f64>()
                / n as f64;
            println!(
                "svr n={n} C={c} eps={eps} threads={threads}: fit {:.2} s, {} iterations, {} SV, train MSE {mse:.5}, peak {:.0} MB",
                fit.as_secs_f64(),
                m.info().iterations,
                m.info().n_support,
                peak_mb()
            );
        }
        "svc" => {
            let p = SvcParams {
                c,
                gamma,
                solver_config,
            };
            let t = Instant::now();
            let m = Svc::fit(x, &data.placement, &p)?;
            let fit = t.elapsed();
            let pred = m.predict(x)?;
            let acc = pred
                .iter()
                .zip(&data.placement)
                .filter(|(a, b)| a == b)
                .count() as f64
                / n as f64;
            let iters: usize = m.info().iter().map(|i| i.iterations).sum();
            println!(
                "svc n={n} k={k} C={c} threads={threads}: fit {:.2} s, {iters} iterations, {} SV, train accuracy {acc:.4}, peak {:.0} MB",
                fit.as_secs_f64(),
                m.n_support(),
                peak_mb()
            );
        }
        "grid" | "cascade" | "query" => {
            let names: Vec<String> = (0..k).map(|p| format!("p{p}")).collect();
            let config = FeatureConfig::default();
            let set = TrainingSet {
                features: x,
                targets: &data.y,
                placements: &data.placement,
                placement_names: &names,
                groups: &data.group,
                feature_config: &config,
            };
            let regressors = if task == "query" {
                RegressorChoice::Fixed { c, epsilon: eps }
            } else {
                RegressorChoice::Grid(GridSpec::default())
            };
            let solver = match args
                .iter()
                .position(|a| a == "--solver")
                .and_then(|i| args.get(i + 1))
                .map(String::as_str)
            {
                None | Some("exact") => Solver::Exact,
                Some("nystrom") => Solver::Nystrom(Nystrom::new(
                    arg(&args, "--landmarks", Nystrom::DEFAULT_LANDMARKS),
                    arg(&args, "--seed", 0),
                )?),
                Some(other) => return Err(format!("unknown solver {other}").into()),
            };
            let storage = match args
                .iter()
                .position(|a| a == "--storage")
                .and_then(|i| args.get(i + 1))
                .map(String::as_str)
            {
                None | Some("projected") => Storage::projected_for(&solver),
                Some("half") => Storage::Half,
                Some(other) => return Err(format!("unknown storage {other}").into()),
            };
            let params = CascadeParams {
                regressors,
                solver_config,
                storage,
                solver,
                ..CascadeParams::default()
            };
            let t = Instant::now();
            let mut last = String::new();
            let mut progress = |e: &ProgressEvent<'_>| {
                let s = format!("{:?}", e.stage);
                if s != last {
                    eprintln!(
                        "[{:7.1} s] {s} ({} steps)",
                        t.elapsed().as_secs_f64(),
                        e.total
                    );
                    last = s;
                }
                true
            };
            let model = Cascade::train(&set, &params, &mut progress)?;
            let train = t.elapsed().as_secs_f64();
            println!(
                "storage: {:?}, solver {:?}",
                model.stored_as(),
                model.solver()
            );
            if let Some(path) = args
                .iter()
                .position(|a| a == "--save")
                .and_then(|i| args.get(i + 1))
            {
                model.save(path)?;
                let mb = std::fs::metadata(path)?.len() as f64 / 1e6;
                println!("saved {path}: {mb:.1} MB");
            }
            let grid_iterations: usize = model.grid_results().iter().map(|r| r.iterations).sum();
            println!(
                "cascade n={n} k={k} threads={threads}: train {train:.1} s, peak {:.0} MB, {grid_iterations} grid iterations",
                peak_mb()
            );
            for (p, name) in names.iter().enumerate() {
                let rp = model.regressor_params(p).unwrap_or_default();
                let best: Vec<f64> = (0..2)
                    .map(|ch| {
                        model
                            .grid_results()
                            .iter()
                            .filter(|r| &r.placement == name && r.channel as usize == ch)
                            .map(|r| r.mse)
                            .fold(f64::INFINITY, f64::min)
                    })
                    .collect();
                println!(
                    "  {}: {} stored samples, chosen {rp:?}, CV MSE {best:?}",
                    names[p],
                    model.stored_samples(p)
                );
            }
            let q = 200.min(n);
            let t = Instant::now();
            for i in 0..q {
                std::hint::black_box(model.predict_one(x.row(i))?);
            }
            let one = t.elapsed().as_secs_f64() / q as f64;
            let t = Instant::now();
            let batch = model.predict(x)?;
            let bt = t.elapsed().as_secs_f64();
            let acc = batch
                .iter()
                .zip(&data.placement)
                .filter(|(a, b)| a.placement == **b)
                .count() as f64
                / n as f64;
            println!(
                "  predict_one {:.3} ms/query; batch {n} in {bt:.2} s = {:.0} queries/s; train placement accuracy {acc:.4}",
                one * 1e3,
                n as f64 / bt
            );
        }
        "export" => {
            let dir = std::path::PathBuf::from(args.get(2).cloned().unwrap_or_else(|| ".".into()));
            std::fs::create_dir_all(&dir)?;
            let bytes = |v: &[f32]| v.iter().flat_map(|f| f.to_le_bytes()).collect::<Vec<u8>>();
            std::fs::write(dir.join("x.f32"), bytes(&data.x))?;
            let y: Vec<f32> = data
                .y
                .iter()
                .flat_map(|v| v.to_array().map(|c| c as f32))
                .collect();
            std::fs::write(dir.join("y.f32"), bytes(&y))?;
            let lab: Vec<u8> = data
                .placement
                .iter()
                .flat_map(|&p| (p as u32).to_le_bytes())
                .collect();
            std::fs::write(dir.join("placement.u32"), lab)?;
            let grp: Vec<u8> = data
                .group
                .iter()
                .flat_map(|&g| (g as u32).to_le_bytes())
                .collect();
            std::fs::write(dir.join("group.u32"), grp)?;
            // The cross-validation folds the cascade uses (per placement, default grid seed),
            // so that scikit-learn can be scored on identical splits (`assign_folds`: feature
            // `bench-internals`).
            let mut fold = vec![0u32; n];
            for p in 0..k {
                let idx: Vec<usize> = (0..n).filter(|&i| data.placement[i] == p).collect();
                let groups: Vec<u64> = idx.iter().map(|&i| data.group[i]).collect();
                let spec = GridSpec::default();
                let (f, _) = ridi_regress::assign_folds(&groups, spec.folds, spec.seed)?;
                for (&i, &fi) in idx.iter().zip(&f) {
                    fold[i] = fi as u32;
                }
            }
            let fb: Vec<u8> = fold.iter().flat_map(|f| f.to_le_bytes()).collect();
            std::fs::write(dir.join("fold.u32"), fb)?;
            std::fs::write(dir.join("shape.txt"), format!("{n} {}\n", data.dim))?;
            println!("exported {n} x {} to {}", data.dim, dir.display());
        }
        other => return Err(format!("unknown task {other}").into()),
    }
    Ok(())
}

fn load_query(args: &[String], n: usize, k: usize) -> Result<(), Box<dyn std::error::Error>> {
    let path = args.get(2).ok_or("load-query needs a model path")?;
    let nq: usize = arg(args, "--queries", 2000);
    let t = Instant::now();
    let model = Cascade::load(path)?;
    let stored: Vec<usize> = (0..k).map(|p| model.stored_samples(p)).collect();
    println!(
        "{path}: {:.1} MB, loaded in {:.2} s; stored samples {stored:?}; {:?}",
        std::fs::metadata(path)?.len() as f64 / 1e6,
        t.elapsed().as_secs_f64(),
        model.stored_as()
    );
    // Held-out sequences: the ones the generator makes after the `n` training rows (same
    // placement signatures). Stream order: consecutive queries mostly share a placement, as
    // when tracking; the shuffled order changes placement at random.
    let all = synth::generate(n + nq, k, 150, 42);
    let dim = all.dim;
    let held_x = all.x[n * dim..].to_vec();
    let held_p = all.placement[n..].to_vec();
    let held_y = all.y[n..].to_vec();
    drop(all);
    // Peak memory from here on: the model and the queries, not the generator's data.
    std::fs::write("/proc/self/clear_refs", "5")?;
    let q = FeatureMatrixRef::new(&held_x, dim)?;
    let stream: Vec<usize> = (0..nq).collect();
    let shuffled = timing::shuffled(nq);
    let one = rayon::ThreadPoolBuilder::new().num_threads(1).build()?;
    let (warm, cold, batch1) = one.install(|| -> Result<_, String> {
        time_one(&model, q, &stream[..nq.min(200)])?;
        let warm = time_one(&model, q, &stream)?;
        let cold = time_one(&model, q, &shuffled)?;
        let (t, c) = (Instant::now(), thread_cpu_s());
        model.predict(q).map_err(|e| e.to_string())?;
        Ok((warm, cold, (t.elapsed().as_secs_f64(), thread_cpu_s() - c)))
    })?;
    let t = Instant::now();
    let batch = model.predict(q)?;
    let bt = t.elapsed().as_secs_f64();
    let acc = batch
        .iter()
        .zip(&held_p)
        .filter(|(a, b)| a.placement == **b)
        .count() as f64
        / nq as f64;
    let rmse = (batch
        .iter()
        .zip(&held_y)
        .map(|(a, t)| (a.velocity - *t).norm().powi(2))
        .sum::<f64>()
        / nq as f64)
        .sqrt();
    println!("held-out velocity RMSE {rmse:.4} m/s");
    println!(
        "predict_one, one thread, {nq} held-out queries: stream order {:.3} ms wall / {:.3} ms CPU, \
         shuffled {:.3} ms wall / {:.3} ms CPU per query",
        warm.0 * 1e3,
        warm.1 * 1e3,
        cold.0 * 1e3,
        cold.1 * 1e3
    );
    println!(
        "batched: one thread {:.0} queries/s wall ({:.0} CPU); {} threads {:.0} queries/s wall; \
         placement accuracy {acc:.4}; peak {:.0} MB",
        nq as f64 / batch1.0,
        nq as f64 / batch1.1,
        rayon::current_num_threads(),
        nq as f64 / bt,
        peak_mb()
    );
    if model.solver() != ridi_regress::Solver::Exact {
        return Ok(());
    }
    let train = synth::generate(n, k, 150, 42);
    let t = Instant::now();
    let r = model.rounding_effect(FeatureMatrixRef::new(&train.x, dim)?, q)?;
    println!(
        "stored samples vs exact f32 rows ({:.1} s): {r}",
        t.elapsed().as_secs_f64()
    );
    Ok(())
}
