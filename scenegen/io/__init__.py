"""Files: the HDF5 layout, reading and writing, atomic writes, validation, export, preview.

The names most users need (``read``, ``write``, ``read_result``, ``write_result``, ...)
are re-exported here from :mod:`scenegen.io.hdf5` and :mod:`scenegen.io.results`;
``scenegen.io.schema`` (the layout), ``scenegen.io.atomic``, ``scenegen.io.validate``,
``scenegen.io.export`` and ``scenegen.io.preview`` are imported on demand.
"""

from scenegen.io.hdf5 import (
    BLOCK_BYTES,
    COMPRESSIONS,
    LIBVER,
    SCHEMA,
    LazyArray,
    atomic_path,
    clean_temp_files,
    describe_open_error,
    describe_read_error,
    describe_temp_file,
    filter_options,
    frames_per_block,
    open_checked,
    read,
    sequence_names,
    temp_file_owner,
    temp_prefix,
    write,
    write_scenario,
)
from scenegen.io.results import TrackerResult, read_result, write_result

__all__ = [
    "BLOCK_BYTES",
    "COMPRESSIONS",
    "LIBVER",
    "SCHEMA",
    "LazyArray",
    "TrackerResult",
    "atomic_path",
    "clean_temp_files",
    "describe_open_error",
    "describe_read_error",
    "describe_temp_file",
    "filter_options",
    "frames_per_block",
    "open_checked",
    "read",
    "read_result",
    "sequence_names",
    "temp_file_owner",
    "temp_prefix",
    "write",
    "write_result",
    "write_scenario",
]
