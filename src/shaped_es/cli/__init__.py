"""The ``shaped-es`` command: ``commands.py`` its commands and their parsers, ``errors.py`` how a command
ends (one error line and exit code, ``error.log``, warnings, MPI supervision), ``info.py`` the commands
that explain (``config``, ``envs``, ``check-env``) and every ``--help``'s defaults, ``check_env.py`` what
an env needs to train here. ``main`` (below) is the console entry point; the module is ``commands`` so
that no submodule shadows it."""


def main(argv=None) -> int:
    """The ``shaped-es`` entry point (``pyproject.toml``: ``shaped_es.cli:main``)."""
    from shaped_es.cli.commands import main as run

    return run(argv)
