"""Plug-in families: one module per plug-in in a package of its own, found by name when the package is
imported. The one discovery every family uses (docs/architecture.md, "Plug-in families"): contact
shapes (:mod:`multibody.shapes`), thrust laws (:mod:`multibody.control.thrust_laws`), section shapes
(:mod:`structures.section_shapes`), optimizers (:mod:`riskassess.stages.optimizers`) and the diagnosis
effects (:mod:`riskassess.diagnosis.effects`, :mod:`riskassess.diagnosis.impact_effects`).

A family's package calls :func:`discover` in its ``__init__`` with the family's interface (a
``typing.Protocol`` the plug-in module satisfies, or a class the plug-in object is an instance of);
adding a plug-in is adding one file to the package. Imports nothing of ours, so every package may
use it.
"""
from __future__ import annotations

import importlib
import pkgutil
from collections.abc import Iterable, Iterator, Mapping


class UnknownPlugin(KeyError, ValueError):
    """A name no plug-in of the family has; the message lists the known ones.

    A ``KeyError``, so ``in`` and ``.get`` behave as on a dict, and a ``ValueError``, so a pydantic
    validator that looks a name up reports it as a validation error of its key.
    """

    def __str__(self) -> str:
        return str(self.args[0])


class PluginError(TypeError):
    """A plug-in module that does not implement its family's interface, or a name given twice."""


class Family(Mapping):
    """Name -> plug-in of one family, in the order of the module names; an unknown name raises
    :class:`UnknownPlugin` listing the known ones.

    Parameters
    ----------
    family : str
        What one plug-in is, singular, for messages (``"thrust law"``).
    plugins : dict
        Name -> plug-in (a module, or the object a module defines).
    """

    def __init__(self, family: str, plugins: dict):
        self.family = family
        self._plugins = dict(plugins)

    def __getitem__(self, name):
        try:
            return self._plugins[name]
        except (KeyError, TypeError):
            raise UnknownPlugin(f"unknown {self.family} {name!r}; the known {self.family}s are: "
                                f"{', '.join(sorted(self._plugins))}") from None

    def __contains__(self, name) -> bool:
        try:
            return name in self._plugins
        except TypeError:        # an unhashable name is no plug-in's
            return False

    def __iter__(self) -> Iterator[str]:
        return iter(self._plugins)

    def __len__(self) -> int:
        return len(self._plugins)

    def __repr__(self) -> str:
        return f"Family({self.family!r}, [{', '.join(self._plugins)}])"


def interface_members(interface) -> list[str]:
    """The names a plug-in module must define to satisfy a ``typing.Protocol``: its annotated
    attributes and its public functions, in the order the protocol declares them.

    Parameters
    ----------
    interface : type
        A ``typing.Protocol`` subclass.

    Returns
    -------
    list of str
    """
    names = list(vars(interface).get("__annotations__", {}))
    names += [n for n, v in vars(interface).items() if callable(v) and not n.startswith("_") and n not in names]
    return names


def check_plugin(plugin, interface, where: str) -> None:
    """Refuse a plug-in that does not implement ``interface``, naming its module and what it lacks.

    Parameters
    ----------
    plugin : module or object
        The plug-in.
    interface : type
        A ``typing.Protocol`` (every member must be defined) or a class (``plugin`` must be an instance).
    where : str
        The plug-in's module name, for the message.

    Raises
    ------
    PluginError
        What is missing.
    """
    if getattr(interface, "_is_protocol", False):
        missing = [name for name in interface_members(interface) if not hasattr(plugin, name)]
        if missing:
            raise PluginError(f"plug-in {where}: {interface.__name__} needs {', '.join(interface_members(interface))}; "
                              f"missing: {', '.join(missing)}")
    elif not isinstance(plugin, interface):
        raise PluginError(f"plug-in {where}: {type(plugin).__name__} is not a {interface.__name__}")


def discover(package: str, path: Iterable[str], family: str, interface, *, key: str = "NAME",
             plugin: str | None = None, skip: Iterable[str] = ()) -> Family:
    """Import every module of a plug-in package (in module-name order) and register its plug-in by name.

    Parameters
    ----------
    package : str
        The package's dotted name (its ``__name__``).
    path : list of str
        Its folders (its ``__path__``; a test may add a folder).
    family : str
        What one plug-in is, singular (``"contact shape"``), for messages.
    interface : type
        What every plug-in implements: a ``typing.Protocol`` the module satisfies, or a class the
        module's ``plugin`` object is an instance of (:func:`check_plugin`).
    key : str
        The plug-in's attribute holding its name (``"NAME"``; an effect's ``"id"``).
    plugin : str, optional
        The module attribute that is the plug-in (an effect's ``"EFFECT"``); default the module itself.
    skip : iterable of str
        Module names that are not plug-ins (the interface's own ``base`` module).

    Returns
    -------
    Family
        Name -> plug-in.

    Raises
    ------
    PluginError
        A module not implementing ``interface``, or two modules giving the same name.
    """
    found, where = {}, {}
    for info in sorted(pkgutil.iter_modules(list(path)), key=lambda m: m.name):
        if info.name in skip or info.name.startswith("_"):
            continue
        module_name = f"{package}.{info.name}"
        module = importlib.import_module(module_name)
        item = module if plugin is None else getattr(module, plugin, None)
        if item is None:
            raise PluginError(f"plug-in {module_name}: a {family} module defines {plugin}")
        check_plugin(item, interface, module_name)
        name = getattr(item, key)
        if not isinstance(name, str) or not name:
            raise PluginError(f"plug-in {module_name}: {key} must be a non-empty string, got {name!r}")
        if name in found:
            raise PluginError(f"plug-ins {where[name]} and {module_name} both name a {family} {name!r}")
        found[name], where[name] = item, module_name
    return Family(family, found)


__all__ = ["Family", "PluginError", "UnknownPlugin", "check_plugin", "discover", "interface_members"]
