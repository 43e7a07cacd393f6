//! The `vrw` command line: parse, call the library, report (STYLE.md point 2).

mod cli;

use clap::Parser;

fn main() {
    let args = match cli::Cli::try_parse() {
        Ok(args) => args,
        // Help and version print as clap prints them; an error quotes at most 200 characters of each input.
        Err(e) if !e.use_stderr() => e.exit(),
        Err(e) => {
            eprint!("{}", cli::clipped_quotes(&e.render().to_string()));
            std::process::exit(e.exit_code());
        }
    };
    if let Err(e) = cli::run(args) {
        // The library's messages already quote their causes; print each cause only once.
        let mut message = e.to_string();
        for cause in e.chain().skip(1).map(ToString::to_string) {
            if !message.contains(&cause) {
                message = format!("{message}: {cause}");
            }
        }
        eprintln!("Error: {}", cli::flags_in(&message));
        std::process::exit(1);
    }
}
