use clap::Parser;

fn main() {
    let cli = knotrod::cli::Cli::parse();
    if let Err(e) = knotrod::cli::main_with(cli) {
        // a closed pipe (e.g. `| head`) is the reader's choice, not an error
        let broken_pipe = e.chain().any(|c| {
            c.downcast_ref::<std::io::Error>()
                .is_some_and(|io| io.kind() == std::io::ErrorKind::BrokenPipe)
        });
        if broken_pipe {
            return;
        }
        eprintln!("error: {e:#}");
        std::process::exit(1);
    }
}
