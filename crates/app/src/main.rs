//! `rt`: the scene editor. With no arguments it opens the built-in Cornell box.

fn main() -> std::process::ExitCode {
    rt_app::launch::main()
}
