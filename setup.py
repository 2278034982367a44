"""Package layout that pyproject.toml cannot express: the repository's top-level ``templates/`` (the one
source of the shipped designs and process profiles) goes into the wheel as ``fabricate/templates``."""

from setuptools import find_packages, setup

setup(
    packages=[*find_packages(include=["fabricate", "fabricate.*"]), "fabricate.templates"],
    package_dir={"fabricate.templates": "templates"},
    package_data={"fabricate": ["py.typed", "report_schema.json"], "fabricate.templates": ["*.toml", "sweeps/*.toml"]},
)
