"""The trackers' Parameters sections are generated from one documentation per field.

``trackers.params.documented`` writes each class's entries from the ``FIELD_DOCS`` of the
parameter dataclasses, with the defaults read from the fields: these tests check that
what a reader sees is what the code does, and that an undocumented field is refused.
"""

import dataclasses
import inspect

import pytest
from numpydoc.docscrape import ClassDoc

import trackers
from trackers.params import TrackerParams, choices, documented, parameter_entries
from trackers.registry import defaults, get_class

NAMES = trackers.names()


def _section(cls: type) -> dict[str, str]:
    """Documented parameter name -> its numpydoc type text, from the class's docstring."""
    doc = ClassDoc(cls, config={"show_class_members": False})
    return {p.name: p.type for p in doc["Parameters"]}


def _default_text(value: object) -> str:
    return f'default "{value}"' if isinstance(value, str) else f"default {value!r}"


@pytest.mark.parametrize("name", NAMES)
def test_every_parameter_is_documented_with_its_default(name):
    cls = get_class(name)
    documented_params = _section(cls)
    assert list(documented_params) == list(defaults(name))  # the same names, in order
    for param, value in defaults(name).items():
        assert documented_params[param].endswith(_default_text(value)), (name, param)


@pytest.mark.parametrize("name", NAMES)
def test_the_params_class_documents_the_same_entries(name):
    params = get_class(name).Params
    assert _section(params) == {k: v for k, v in _section(get_class(name)).items()
                                if k != "rng"}
    assert "{parameters}" not in (params.__doc__ or "")


def test_choice_sets_come_from_the_checks_constants():
    from trackers.filters.resampling import RESAMPLERS
    from trackers.particle import WEIGHTINGS

    entries = _section(get_class("ps"))
    assert entries["resampler"].startswith(choices(RESAMPLERS))
    assert entries["weighting"].startswith(choices(WEIGHTINGS))


_DOC = """A test class.

    Parameters
    ----------
    {parameters}
    """


def _decorate(name, base, fields, docs=None, doc=_DOC):
    """Decorate a new parameter dataclass ``name`` (fields: (name, type, default))."""
    namespace = {"__doc__": doc}
    if docs is not None:
        namespace["FIELD_DOCS"] = docs
    cls = dataclasses.make_dataclass(name, fields, bases=(base,), frozen=True,
                                     namespace=namespace)
    return documented()(cls)


def test_an_undocumented_field_is_refused_naming_it():
    from trackers.particle import ParticleParams

    with pytest.raises(TypeError, match=r"WiderParams: parameter 'n_rings' .*WiderParams"):
        _decorate("WiderParams", ParticleParams, [("n_rings", int, 2)])
    documented_ = _decorate("WiderParams", ParticleParams, [("n_rings", int, 2)],
                            docs={"n_rings": ("int", "Rings.")})
    assert "n_rings : int, default 2\n        Rings." in documented_.__doc__


def test_a_redeclared_field_must_be_documented_again():
    """A subclass that redeclares a field (say with another default) documents it: the
    base's text may speak of the base's default."""
    from trackers.annealed import AnnealedParams

    with pytest.raises(TypeError, match="'n_layers'"):
        _decorate("DeeperParams", AnnealedParams, [("n_layers", int, 5)])


def test_a_stale_entry_and_a_missing_marker_are_refused():
    with pytest.raises(TypeError, match="documents gone"):
        _decorate("StaleParams", TrackerParams, [], docs={"gone": ("int", "Gone.")})
    with pytest.raises(TypeError, match="one line '{parameters}'"):
        _decorate("NoMarkerParams", TrackerParams, [], doc="No marker.")


def test_entries_keep_the_docstring_indentation_and_extras_follow():
    @documented(extra={"rng": ("int", "Seed.")})
    class Tool(trackers.BaseTracker):
        """A tool.

        Parameters
        ----------
        {parameters}

        Notes
        -----
        Nothing.
        """

        name = "tool"
        Params = get_class("meanshift").Params

        def _init(self, frame, boxes):  # pragma: no cover
            pass

        def _step(self, frame):  # pragma: no cover
            pass

    doc = inspect.getdoc(Tool)
    lines = parameter_entries(Tool.Params)
    assert "\n".join([*lines, "rng : int", "    Seed."]) in doc
    assert list(_section(Tool)) == ["kernel", "bins", "max_iter", "eps", "rng"]
    assert doc.endswith("Notes\n-----\nNothing.")


def test_a_parameter_dataclass_gets_the_standard_raises_section_once():
    # Written once (trackers.params.PARAMS_RAISES) instead of in every dataclass; a
    # docstring with a Raises section of its own keeps it alone.
    from trackers.params import PARAMS_RAISES
    from trackers.particle import ParticleParams

    made = _decorate("WiderParams", ParticleParams, [("n_rings", int, 2)],
                     docs={"n_rings": ("int", "Rings.")})
    doc = ClassDoc(made, config={"show_class_members": False})
    assert [(e.type, e.desc) for e in doc["Raises"]] == [("ValueError", [PARAMS_RAISES[3].strip()])]
    own = _decorate("OwnParams", TrackerParams, [],
                    doc="Own.\n\n    Parameters\n    ----------\n    {parameters}\n\n"
                        "    Raises\n    ------\n    KeyError\n        Never.\n    ")
    assert [e.type for e in ClassDoc(own, config={"show_class_members": False})["Raises"]] == \
        ["KeyError"]
    for name in NAMES:
        assert inspect.getdoc(get_class(name).Params).count("\nRaises\n") == 1, name
