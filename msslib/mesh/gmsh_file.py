"""What meshio does not keep of a gmsh file: the names of its physical groups with their dimension
(:func:`physical_names`) and, in gmsh 4, the physical groups of each entity (:func:`entity_groups`),
read from the file itself."""

from __future__ import annotations

from pathlib import Path

__all__ = ["physical_names", "entity_groups"]

#: the sections of a gmsh file that follow $PhysicalNames (where the search for it stops)
LATER_SECTIONS = (b"$Entities", b"$PartitionedEntities", b"$Nodes", b"$Elements")


def physical_names(path: Path) -> dict | None:
    """``{(dim, tag): name}`` of every physical group in the ``$PhysicalNames`` section of a gmsh
    file (text in ASCII and binary files alike), or None for a file that is not a gmsh file.

    meshio keeps these names in ``field_data``, a dict keyed by name: of a physical surface and a
    physical volume of one name it keeps only one, and the elements of the other would lose their
    name (and be known by their number).  Only the start of the file is read."""
    try:
        with open(path, "rb") as f:
            if f.readline().strip() != b"$MeshFormat":
                return None
            for line in f:
                line = line.strip()
                if line == b"$PhysicalNames":
                    break
                if line in LATER_SECTIONS:
                    return {}
            else:
                return {}
            names = {}
            for _ in range(int(f.readline())):
                dim, tag, name = f.readline().decode("utf-8").strip().split(maxsplit=2)
                if len(name) >= 2 and name[0] == name[-1] == '"':
                    name = name[1:-1]
                names[(int(dim), int(tag))] = name
            return names
    except (OSError, ValueError):  # meshio has read the file: keep its names
        return None


def entity_groups(path: Path) -> dict | None:
    """``{(dim, entity tag): [physical tags]}`` from the ``$Entities`` section of a gmsh 4 file
    (ASCII or binary, format 4.0 or 4.1), or None when the file has none (gmsh 2, or not gmsh).

    In gmsh 4 the physical groups belong to the entities, and an element to one entity: its groups
    are all those of its entity.  meshio keeps the first only (``gmsh:physical``), so a group whose
    entities also carry another group loses its elements; this is the full list."""
    import struct

    try:
        with open(path, "rb") as f:
            if f.readline().strip() != b"$MeshFormat":
                return None
            version, file_type, data_size = f.readline().split()[:3]
            major = int(float(version))
            if major != 4:
                return None
            binary, size_t = int(file_type) == 1, int(data_size)
            order = "<"
            if binary:
                one = f.read(4)
                order = "<" if struct.unpack("<i", one)[0] == 1 else ">"
            for line in f:
                line = line.strip()
                if line == b"$Entities":
                    break
                if line in (b"$PartitionedEntities", b"$Nodes", b"$Elements"):
                    return None
            else:
                return None
            n_bbox = 6 if float(version) < 4.1 else 3  # the coordinates of a point entity
            groups = {}
            if not binary:
                tokens = []
                for line in f:
                    if line.strip() == b"$EndEntities":
                        break
                    tokens.extend(line.split())
                pos = 4
                counts = [int(t) for t in tokens[:4]]
                for dim, count in enumerate(counts):
                    for _ in range(count):
                        tag = int(tokens[pos])
                        pos += 1 + (n_bbox if dim == 0 else 6)
                        n_phys = int(tokens[pos])
                        groups[(dim, tag)] = [int(t) for t in tokens[pos + 1:pos + 1 + n_phys]]
                        pos += 1 + n_phys
                        if dim > 0:
                            pos += 1 + int(tokens[pos])
                return groups
            st = {8: "Q", 4: "I"}[size_t]

            def read(fmt):
                fmt = order + fmt
                return struct.unpack(fmt, f.read(struct.calcsize(fmt)))

            counts = read(f"4{st}")
            for dim, count in enumerate(counts):
                for _ in range(count):
                    (tag,) = read("i")
                    read(f"{n_bbox if dim == 0 else 6}d")
                    (n_phys,) = read(st)
                    groups[(dim, tag)] = list(read(f"{n_phys}i"))
                    if dim > 0:
                        (n_bound,) = read(st)
                        read(f"{n_bound}i")
            return groups
    except (OSError, ValueError, IndexError, KeyError, struct.error):  # meshio has read the file: its tags
        return None
