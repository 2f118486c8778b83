"""The lab: running trackers on sequences, the papers' experiments, the bench, the report
and fixture regeneration. The lab may import the library and :mod:`trackers`; the library
never imports the lab.
"""

__all__: list[str] = []
