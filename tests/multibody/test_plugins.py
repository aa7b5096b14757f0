"""The one plug-in discovery (multibody/maths/plugins.py) every family uses: adding a plug-in is adding one
file, an unknown name is an error listing the known ones, a module that does not implement the
family's interface or repeats a name is refused naming its module. Each family's own unknown-name
test sits with the family (tests/multibody/test_shapes.py, control/test_thrust_laws.py,
tests/structures/test_sections.py, tests/riskassess/stages/test_identify.py,
tests/riskassess/diagnosis/test_effects.py and test_impact.py)."""
from __future__ import annotations

import importlib
import sys
import textwrap
from types import SimpleNamespace

import pytest

from multibody.maths.plugins import Family, PluginError, UnknownPlugin, discover

#: A family's package as a user would write one: its interface and the one discovery call.
PACKAGE_INIT = textwrap.dedent('''
    """A plug-in family of springs, one file each."""
    from typing import Protocol

    from multibody.maths.plugins import discover


    class Spring(Protocol):
        NAME: str

        def force(self, elongation):
            """Tension (N) at an elongation (m)."""


    SPRINGS = discover(__name__, __path__, "spring", Spring, skip=("base",))
''')

LINEAR = 'NAME = "linear"\n\n\ndef force(elongation):\n    return 2.0 * elongation\n'
CUBIC = 'NAME = "cubic"\n\n\ndef force(elongation):\n    return 3.0 * elongation ** 3\n'


@pytest.fixture
def springs_package(tmp_path, monkeypatch):
    """A new package ``springs_probe`` in ``tmp_path`` with the family's __init__ and one spring; its
    modules are dropped from sys.modules afterwards."""
    package = tmp_path / "springs_probe"
    package.mkdir()
    (package / "__init__.py").write_text(PACKAGE_INIT)
    (package / "linear.py").write_text(LINEAR)
    (package / "base.py").write_text("HELP = 'not a plug-in: skipped by name'\n")
    monkeypatch.syspath_prepend(str(tmp_path))
    yield package
    for name in [m for m in sys.modules if m == "springs_probe" or m.startswith("springs_probe.")]:
        del sys.modules[name]


def test_a_file_dropped_into_the_package_is_a_new_plug_in(springs_package):
    probe = importlib.import_module("springs_probe")
    assert isinstance(probe.SPRINGS, Family) and list(probe.SPRINGS) == ["linear"]
    (springs_package / "cubic.py").write_text(CUBIC)            # adding one is adding one file
    found = discover("springs_probe", probe.__path__, "spring", probe.Spring, skip=("base",))
    assert list(found) == ["cubic", "linear"]                     # module-name order
    # the plug-ins are the files' own functions: 3 x^3 at x = 2 m is 24 N, 2 x is 4 N
    assert found["cubic"].force(2.0) == 24.0 and found["linear"].force(2.0) == 4.0


def test_an_unknown_name_is_an_error_listing_the_known_ones(springs_package):
    (springs_package / "cubic.py").write_text(CUBIC)
    springs = importlib.import_module("springs_probe").SPRINGS
    with pytest.raises(ValueError) as unknown:
        springs["helical"]
    assert str(unknown.value) == "unknown spring 'helical'; the known springs are: cubic, linear"
    assert isinstance(unknown.value, KeyError) and isinstance(unknown.value, UnknownPlugin)
    # a KeyError as well, so the dict idioms keep their meaning
    assert "helical" not in springs and springs.get("helical") is None and "linear" in springs
    assert [] not in springs                                      # an unhashable name is no plug-in's


def test_a_module_missing_part_of_the_interface_is_refused_naming_it(springs_package):
    (springs_package / "broken.py").write_text('NAME = "broken"\n')
    with pytest.raises(PluginError, match=r"springs_probe\.broken: Spring needs NAME, force; missing: force"):
        importlib.import_module("springs_probe")


def test_two_modules_giving_one_name_are_refused_naming_both(springs_package):
    (springs_package / "linear_again.py").write_text(LINEAR)
    with pytest.raises(PluginError, match=r"springs_probe\.linear and springs_probe\.linear_again both name a "
                                          r"spring 'linear'"):
        importlib.import_module("springs_probe")


def test_object_plug_ins_are_checked_against_their_class(tmp_path, monkeypatch):
    """The effect families register the ``EFFECT`` object each module defines, keyed by its ``id``,
    and refuse one that is not an instance of the family's class."""
    package = tmp_path / "gadgets_probe"
    package.mkdir()
    (package / "__init__.py").write_text("")
    (package / "one.py").write_text("from types import SimpleNamespace\n\nEFFECT = SimpleNamespace(id='first')\n")
    monkeypatch.syspath_prepend(str(tmp_path))
    try:
        found = discover("gadgets_probe", [str(package)], "gadget", SimpleNamespace, key="id", plugin="EFFECT")
        assert list(found) == ["first"] and found["first"].id == "first"
        (package / "two.py").write_text("EFFECT = 3\n")
        with pytest.raises(PluginError, match=r"gadgets_probe\.two: int is not a SimpleNamespace"):
            discover("gadgets_probe", [str(package)], "gadget", SimpleNamespace, key="id", plugin="EFFECT")
        (package / "two.py").write_text("OTHER = 3\n")
        sys.modules.pop("gadgets_probe.two")
        with pytest.raises(PluginError, match=r"gadgets_probe\.two: a gadget module defines EFFECT"):
            discover("gadgets_probe", [str(package)], "gadget", SimpleNamespace, key="id", plugin="EFFECT")
    finally:
        for name in [m for m in sys.modules if m == "gadgets_probe" or m.startswith("gadgets_probe.")]:
            del sys.modules[name]
