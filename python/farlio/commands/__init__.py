"""One module per `farlio` subcommand: each has add_arguments(parser) and run(args)."""
