//! The `vrw` command line: parse, call the library, report (STYLE.md point 2).

mod cli;

use clap::Parser;

fn main() {
    let args = cli::Cli::parse();
    if let Err(e) = cli::run(args) {
        // The library's messages already quote their causes; print each cause only once.
        let mut message = e.to_string();
        for cause in e.chain().skip(1).map(ToString::to_string) {
            if !message.contains(&cause) {
                message = format!("{message}: {cause}");
            }
        }
        eprintln!("Error: {message}");
        std::process::exit(1);
    }
}
