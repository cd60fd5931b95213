"""Packaging beyond what pyproject.toml can say: ``examples/`` (at the top of the source,
where the README runs them) is installed as the package data ``moas_gui.examples``."""

from setuptools import find_namespace_packages, setup

setup(packages=[*find_namespace_packages(include=["moas_gui*"], exclude=["*__pycache__*"]),
                "moas_gui.examples"],
      package_dir={"moas_gui.examples": "examples"})
