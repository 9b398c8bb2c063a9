//! `fourfold tree`: build the 16-tree and print its statistics, as a table or JSON.

use clap::Args;

use fourfold::render::Prepared;
use fourfold::tree::BuildSettings;

use crate::failure::Failure;
use crate::input::{Input, Warn, checked, compile_warning, load_scene, override_tree};

#[derive(Debug, Clone, Args)]
pub struct TreeArgs {
    #[command(flatten)]
    pub input: Input,
    /// Deepest level of the 16-tree (the scene's, else 6): each level halves the boxes'
    /// sides; boxes that may hold M are split down to it.
    #[arg(long, allow_hyphen_values = true)]
    pub max_level: Option<u32>,
    /// Level down to which every box is split, whatever the interval test says (the
    /// scene's, else 4; at most --max-level).
    #[arg(long, allow_hyphen_values = true)]
    pub min_level: Option<u32>,
    /// Most nodes the tree may keep.
    #[arg(long, allow_hyphen_values = true)]
    pub node_budget: Option<u32>,
    /// Print one JSON object instead of a table.
    #[arg(long)]
    pub json: bool,
    /// Build on one thread.
    #[arg(long)]
    pub single_thread: bool,
}

/// `fourfold tree`.
pub fn tree(args: &TreeArgs, warn: Warn) -> Result<String, Failure> {
    let mut scene = load_scene(&args.input)?;
    override_tree(&mut scene, args.max_level, args.min_level, args.node_budget);
    let scene = checked(scene)?;
    let formula = compile_warning(&scene, warn)?;
    let settings: BuildSettings = scene.tree.into();
    let build = || Prepared::new(&formula, &scene);
    let prepared = if args.single_thread {
        rayon::ThreadPoolBuilder::new()
            .num_threads(1)
            .build()
            .map_err(|e| Failure::runtime(format!("cannot start a thread pool: {e}")))?
            .install(build)
    } else {
        build()
    }
    .map_err(|e| Failure::runtime(e.to_string()))?;
    if args.json {
        return Ok(prepared.tree_report(settings).to_string());
    }
    let Prepared {
        tree, hierarchy, ..
    } = prepared;
    let s = &tree.stats;
    let mut out = String::new();
    out.push_str(&format!(
        "16-tree of F = {}\nlevels {}..{} (min..max), node budget {}\n\n",
        formula.f_text(),
        settings.min_level,
        settings.max_level,
        settings.node_budget
    ));
    out.push_str("level      kept    leaves  discarded\n");
    for l in 0..s.nodes_per_level.len().max(s.discarded_per_level.len()) {
        out.push_str(&format!(
            "{l:>5} {:>9} {:>9} {:>10}\n",
            s.nodes_per_level.get(l).copied().unwrap_or(0),
            s.leaves_per_level.get(l).copied().unwrap_or(0),
            s.discarded_per_level.get(l).copied().unwrap_or(0),
        ));
    }
    out.push_str(&format!(
        "\nnodes {}, leaves {}, hierarchy for the GPU {} bytes ({} nodes, marched as {}), {} interval evaluations, built in {:.1} ms\n",
        s.nodes,
        s.leaves,
        hierarchy.bytes(),
        hierarchy.nodes.len(),
        hierarchy.march_summary(),
        s.interval_evaluations,
        s.build_ms
    ));
    if s.mean_value_discarded > 0 {
        out.push_str(&format!(
            "discarded by the mean-value form of F (the natural interval extension held 0): {}\n",
            s.mean_value_discarded
        ));
    }
    if tree.is_empty() {
        out.push_str(
            "no surface in this domain: F has no zero in the box (try a larger --domain)\n",
        );
    }
    if let Some(note) = fourfold::render::verdict::touching_note(s) {
        out.push_str(&format!("note: {note}\n"));
    }
    if s.budget_hit {
        out.push_str(&format!(
            "node budget hit: refinement stopped after level {} (raise --node-budget or lower --max-level)\n",
            s.budget_level.unwrap_or(0)
        ));
    }
    if s.singular_boxes > 0 {
        out.push_str(&format!(
            "{} boxes at the maximum level may hold a critical point of F (0 in every partial): \
             M may be singular there\n",
            s.singular_boxes
        ));
    }
    Ok(out)
}
