//! Undo and redo as the window does them (the steps themselves are `history.rs`'s), and the
//! window's keyboard shortcuts.

use eframe::egui;

use crate::history::{self, Snapshot};

use super::FourfoldApp;

impl FourfoldApp {
    /// Shows this frame's state to the history. Auto-rotation's turning is not a change the
    /// user made, so while it runs the angles are left out.
    pub(crate) fn record_history(&mut self, ctx: &egui::Context) {
        let mut now = self.snapshot();
        if self.ui.auto_rotate
            && let Some(settled) = self.history.settled()
        {
            now.scene.view.angles = settled.scene.view.angles;
        }
        let dragging = ctx.input(|i| i.pointer.any_down());
        self.history.observe(&now, dragging);
        if self.history.settling(&now) {
            // Come back when the change has settled, even if nothing else happens.
            ctx.request_repaint_after(history::SETTLE);
        }
    }

    /// What undo and redo restore.
    pub(crate) fn snapshot(&self) -> Snapshot {
        Snapshot {
            scene: self.session.scene.clone(),
            text: self.session.text.clone(),
        }
    }

    /// Goes back to `to`: only what changed is rebuilt (a new formula compiles again; new
    /// parameters, domain or tree settings rebuild the tree; the rest is the view).
    pub(crate) fn restore(&mut self, to: Snapshot) {
        let gpu = self.gpu.clone();
        let s = &mut self.session;
        if to.text == s.text && to.scene.formula == s.scene.formula {
            let rebuild = to.scene.params != s.scene.params
                || to.scene.domain != s.scene.domain
                || to.scene.tree != s.scene.tree;
            let brute_force = to.scene.render.brute_force;
            let current_brute_force = s.scene.render.brute_force;
            s.scene = to.scene;
            // Brute force switches once its pipeline is warm (Session::set_brute_force).
            s.scene.render.brute_force = current_brute_force;
            if rebuild {
                s.rebuild_tree(gpu.as_ref());
            }
            s.set_brute_force(brute_force, gpu.as_ref());
        } else {
            s.load_scene(to.scene, gpu.as_ref());
            if to.text != s.text {
                s.set_text(&to.text, gpu.as_ref());
            }
        }
        self.fit_pending = false;
    }

    pub fn undo(&mut self) {
        let now = self.snapshot();
        if let Some(to) = self.history.undo(&now) {
            self.restore(to);
        }
    }

    pub fn redo(&mut self) {
        let now = self.snapshot();
        if let Some(to) = self.history.redo(&now) {
            self.restore(to);
        }
    }

    /// The keys that act on the whole window, when no text field has the keyboard: F fits,
    /// Ctrl+Z undoes, Ctrl+Shift+Z and Ctrl+Y redo.
    pub(crate) fn shortcuts(&mut self, ctx: &egui::Context) {
        if ctx.egui_wants_keyboard_input() {
            return;
        }
        use egui::{Key, KeyboardShortcut, Modifiers};
        let redo = KeyboardShortcut::new(Modifiers::COMMAND | Modifiers::SHIFT, Key::Z);
        let redo_y = KeyboardShortcut::new(Modifiers::COMMAND, Key::Y);
        let undo = KeyboardShortcut::new(Modifiers::COMMAND, Key::Z);
        let fit = KeyboardShortcut::new(Modifiers::NONE, Key::F);
        let (redo, undo, fit) = ctx.input_mut(|i| {
            let redo = i.consume_shortcut(&redo) || i.consume_shortcut(&redo_y);
            (redo, i.consume_shortcut(&undo), i.consume_shortcut(&fit))
        });
        if redo {
            self.redo();
        } else if undo {
            self.undo();
        }
        if fit {
            self.fit();
        }
    }
}
