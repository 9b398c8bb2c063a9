use fourfold::CompiledFormula;
use fourfold::render::pipeline::{Device, render_prepared};
use fourfold::render::{Gpu, Prepared};
use fourfold::render::certify::Verdict;
use fourfold::scene::Scene;
fn main() {
    let args: Vec<String> = std::env::args().collect();
    let text = std::fs::read_to_string(&args[1]).unwrap();
    let mut scene = Scene::parse(&text, "x").unwrap();
    scene.render.certified = true;
    scene.render.rays = 4;
    let n: u32 = args[2].parse().unwrap();
    let f = CompiledFormula::compile(&scene.formula).unwrap();
    let p = Prepared::new(&f, &scene).unwrap();
    let gpu = Gpu::new().unwrap();
    let g = render_prepared(&scene, &f, &p, n, n, Device::Gpu(&gpu), Default::default()).unwrap();
    let c = render_prepared(&scene, &f, &p, n, n, Device::Cpu, Default::default()).unwrap();
    for (x, y) in [(86u32, 47u32), (76, 48), (90, 48), (55, 52), (60, 60)] { dump(&g.rgba, n, x, y); }
    let (gv, cv) = (g.verdicts.unwrap(), c.verdicts.unwrap());
    let mut shown = 0;
    for i in 0..gv.len() {
        if gv[i] != cv[i] {
            if shown < 20 { println!("px {} {} gpu {:?} cpu {:?}", i as u32 % n, i as u32 / n, gv[i], cv[i]); }
            shown += 1;
        }
    }
    println!("{shown} differ");
    let und: Vec<usize> = (0..cv.len()).filter(|&i| cv[i] == Verdict::Undecided).collect();
    println!("cpu undecided {}: {:?}", und.len(), und.iter().take(12).map(|&i| (i as u32 % n, i as u32 / n)).collect::<Vec<_>>());
    let _ = Verdict::Hit;
}
#[allow(dead_code)]
fn dump(g: &[u8], n: u32, px: u32, py: u32) {
    let i = ((py * n + px) * 4) as usize;
    println!("px {px} {py}: outside {} excluded {} centre-in {}", g[i], g[i+1], g[i+2]);
}
