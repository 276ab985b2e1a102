"""Lazy package namespaces (PEP 562): a package's public names load their module on first use,
so importing the package, or one light module of it, stays cheap."""

import importlib

__all__ = ["lazy_exports"]


def lazy_exports(package, exports, subpackages=()):
    """`(__getattr__, __dir__)` for `package` whose names `exports` maps to their module.

    A module is absolute (``"pitotcal.io"``) or relative to the package (``".planner"``).
    `subpackages` names the package's subpackages that load on first use too
    (``pitotcal.studies.run_study`` after ``import pitotcal`` alone).
    """
    namespace = importlib.import_module(package).__dict__

    def __getattr__(name):
        if name in subpackages:
            value = importlib.import_module(f"{package}.{name}")
        elif name in exports:
            value = getattr(importlib.import_module(exports[name], package), name)
        else:
            raise AttributeError(f"module {package!r} has no attribute {name!r}")
        namespace[name] = value
        return value

    def __dir__():
        return sorted({*namespace, *exports, *subpackages})

    return __getattr__, __dir__
