"""One module per ``react3d`` sub-command; each defines HELP, add_arguments(parser) and run(args) -> int."""
