"""The ``shaped-es`` command: ``main.py`` its commands and their parsers, ``errors.py`` how a command ends
(one error line and exit code, ``error.log``, warnings, MPI supervision), ``info.py`` the commands that
explain (``config``, ``envs``, ``check-env``) and every ``--help``'s defaults, ``check_env.py`` what an
env needs to train here."""


def main(argv=None) -> int:
    """The ``shaped-es`` entry point (``pyproject.toml``: ``shaped_es.cli:main``)."""
    from shaped_es.cli.main import main as run

    return run(argv)
