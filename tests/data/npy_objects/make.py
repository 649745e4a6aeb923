#!/usr/bin/python3
"""Writes the test files of tests/io/npy_objects_test.cc into this folder (README.md lists them).

Run from anywhere with Debian's Python and NumPy (1.24 made the files here):
    /usr/bin/python3 tests/data/npy_objects/make.py
The values are fixed patterns, so that the test states them without reading them from here.
gt_Living.npy is not made here: it is VPR-Bench's file (SOURCE.md).
"""
import io
import os
import pickle
import struct
import zipfile
import zlib

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))


def write(name, data):
    with open(os.path.join(HERE, name), "wb") as f:
        f.write(data)


def saved(array):
    """The bytes np.save writes (for an object array: a pickle of protocol 3)."""
    out = io.BytesIO()
    np.save(out, array, allow_pickle=True)
    return out.getvalue()


def npy_with_pickle(array, protocol):
    """A .npy file as np.save writes it, but with a pickle of another protocol."""
    out = io.BytesIO()
    np.lib.format.write_array_header_1_0(out, np.lib.format.header_data_from_array_1_0(array))
    return out.getvalue() + pickle.dumps(array, protocol=protocol)


def object_array(values):
    """A 1-D object array of `values` (np.array would make a 2-D array of equal-length lists)."""
    array = np.empty(len(values), dtype=object)
    for i, v in enumerate(values):
        array[i] = v
    return array


# gt_lists.npy: a (4, 2) ground truth as VPR-Bench lays it out, [query, [references]].
gt = np.empty((4, 2), dtype=object)
for q, refs in enumerate([[0, 1], [1, 2, 3], [], [2**40, -5]]):
    gt[q, 0] = q
    gt[q, 1] = refs
write("gt_lists.npy", saved(gt))

# mixed.npy and mixed_p{0,2,5}.npy: one object array of each kind of value a user may store.
shared = [5]
mixed = object_array([
    np.array([4, 5, 6], dtype=np.int64),                          # 0: a NumPy int array
    np.int32(7),                                                  # 1: a NumPy scalar
    (8, 9),                                                       # 2: a tuple
    range(2, 5),                                                  # 3: a range
    [[1, 2], [3]],                                                # 4: nested lists
    np.asfortranarray(np.arange(6, dtype="<u2").reshape(2, 3)),   # 5: Fortran order, 0..5
    # 6: NumPy bool and float scalars, None, text, bytes, a 64-bit int, a Python float
    [np.bool_(True), np.float64(0.5), None, "text", b"\x00\xff", -2**40, 0.25],
    {"key": 1},                                                   # 7: a dict
    np.zeros(0, dtype=np.int64),                                  # 8: an empty array
    object_array([None, 1]),                                      # 9: a nested object array
    [shared, shared],                                             # 10: one list twice
])
write("mixed.npy", saved(mixed))
for protocol in (0, 2, 5):
    write("mixed_p%d.npy" % protocol, npy_with_pickle(mixed, protocol))

# numeric_fortran.npy: int32 [[-2, -1, 0], [1, 2, 3]] stored in Fortran order.
write("numeric_fortran.npy", saved(np.asfortranarray(np.arange(-2, 4, dtype="<i4").reshape(2, 3))))

# evil.npy: a (1,) object array whose pickle calls posix.system (os.system) on load, written by
# hand. The command only prints; the reader must refuse it without running anything.
evil = (b"\x80\x02cposix\nsystem\nq\x00X\x2d\x00\x00\x00"
        b"echo OpenABLE test: this command must not run\x85q\x01Rq\x02.")
assert len(b"echo OpenABLE test: this command must not run") == 0x2d
header = io.BytesIO()
np.lib.format.write_array_header_1_0(
    header, {"descr": "|O", "fortran_order": False, "shape": (1,)})
write("evil.npy", header.getvalue() + evil)

# gt.npz (np.savez, stored) and gt_compressed.npz (np.savez_compressed, deflated): VPR_Tutorial's
# GT.npz layout. GThard is the 4 x 4 identity, GTsoft is true where |i - j| <= 1.
i, j = np.indices((4, 4))
hard = np.eye(4, dtype=bool)
soft = np.abs(i - j) <= 1
out = io.BytesIO()
np.savez(out, GThard=hard, GTsoft=soft)
stored = out.getvalue()
write("gt.npz", stored)
out = io.BytesIO()
np.savez_compressed(out, GThard=hard, GTsoft=soft)
write("gt_compressed.npz", out.getvalue())

# gt_damaged_crc.npz: gt.npz with the first data byte of GTsoft.npy (element (0, 0), True)
# set to 0: the archive is intact, the member fails its CRC-32.
with zipfile.ZipFile(io.BytesIO(stored)) as z:
    info = z.getinfo("GTsoft.npy")
name_size, extra_size = struct.unpack("<HH", stored[info.header_offset + 26:info.header_offset + 30])
member_start = info.header_offset + 30 + name_size + extra_size
npy_header_size = 10 + struct.unpack("<H", stored[member_start + 8:member_start + 10])[0]
damaged = bytearray(stored)
assert damaged[member_start + npy_header_size] == 1
damaged[member_start + npy_header_size] = 0
write("gt_damaged_crc.npz", bytes(damaged))


def zip64_archive(name, data):
    """A ZIP archive of one stored member in which every size and offset that may be is in zip64
    fields: the central directory's sizes and offset hold 0xFFFFFFFF, a zip64 end record and its
    locator precede the end record (PKWARE's APPNOTE.TXT, 4.3.14-4.3.16 and 4.5.3)."""
    crc = zlib.crc32(data)
    name = name.encode()
    local_extra = struct.pack("<HHQQ", 1, 16, len(data), len(data))
    local = struct.pack("<I5H3I2H", 0x04034B50, 45, 0, 0, 0, 0x21, crc, 0xFFFFFFFF, 0xFFFFFFFF,
                        len(name), len(local_extra)) + name + local_extra
    central_extra = struct.pack("<HHQQQ", 1, 24, len(data), len(data), 0)
    central = struct.pack("<I6H3I5H2I", 0x02014B50, 45, 45, 0, 0, 0, 0x21, crc, 0xFFFFFFFF,
                          0xFFFFFFFF, len(name), len(central_extra), 0, 0, 0, 0,
                          0xFFFFFFFF) + name + central_extra
    directory = len(local) + len(data)
    end64 = struct.pack("<IQ2H2I4Q", 0x06064B50, 44, 45, 45, 0, 0, 1, 1, len(central), directory)
    locator = struct.pack("<2IQI", 0x07064B50, 0, directory + len(central), 1)
    end = struct.pack("<I4H2IH", 0x06054B50, 0, 0, 0xFFFF, 0xFFFF, 0xFFFFFFFF, 0xFFFFFFFF, 0)
    return local + data + central + end64 + locator + end


# zip64.npz: GThard.npy, the 3 x 3 identity, in such an archive.
archive = zip64_archive("GThard.npy", saved(np.eye(3, dtype=bool)))
with zipfile.ZipFile(io.BytesIO(archive)) as z:  # Python's zipfile reads it
    assert (np.load(io.BytesIO(z.read("GThard.npy"))) == np.eye(3, dtype=bool)).all()
write("zip64.npz", archive)
