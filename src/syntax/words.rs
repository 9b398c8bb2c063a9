//! The words of the formula language that are not parameters: the function names and the
//! named constants. The parser colours them; lowering gives them their meaning.

/// The function names of the language.
pub const FUNCTIONS: &[&str] = &[
    "sin", "cos", "tan", "asin", "acos", "atan", "sinh", "cosh", "tanh", "exp", "ln", "log",
    "sqrt", "cbrt", "abs", "sign", "step", "min", "max", "pow", "atan2",
];

/// Named constants of the language.
pub const CONSTANTS: &[(&str, f64)] = &[
    ("pi", std::f64::consts::PI),
    ("tau", std::f64::consts::TAU),
    ("e", std::f64::consts::E),
];
