//! What a scene makes: pictures, the tree, the shader, animations, slice meshes and the
//! sweep's critical values, each as the command of the same name makes it.

pub mod animate;
pub mod critical;
pub mod mesh;
pub mod picture;
pub mod tree;
