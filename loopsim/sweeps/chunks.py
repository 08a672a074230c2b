"""Where the cases go: the fixed order of positions, the chunks of a sweep and the pieces
still to compute (a function of the configuration and the files already there)."""
from .. import storage


case_order = storage.case_order


def canonical_chunks(config):
    """The chunks of ``config.chunk_size`` consecutive positions (the last one shorter)."""
    size, count = config.chunk_size, len(config.cases)
    return [range(start, min(start + size, count)) for start in range(0, count, size)]


def chunk_case_ids(config, chunk):
    """Sorted case ids of a piece of work: ``chunk`` a range of positions (see
    :func:`case_order`), or an int k, the k-th of :func:`canonical_chunks`."""
    if not isinstance(chunk, range):
        chunk = canonical_chunks(config)[int(chunk)]
    order = case_order(len(config.cases))
    return sorted(order[p] for p in chunk)


def pending_pieces(config, covered, shard=None):
    """Position ranges still to compute: every chunk (of shard ``(i, n)``: the chunks k
    with k % n == i) less the positions ``covered`` (ranges of the files already there).
    A function of the configuration, the chunk size and the files only, so identical
    sweeps run side by side compute the same pieces and write the same file names; a
    changed chunk size only cuts the remaining positions differently (no case is lost or
    computed twice)."""
    pieces = []
    for k, chunk in enumerate(canonical_chunks(config)):
        if shard is not None and k % shard[1] != shard[0]:
            continue
        start = chunk.start
        for low, high in sorted(covered):
            if high <= start or low >= chunk.stop:
                continue
            if low > start:
                pieces.append(range(start, low))
            start = max(start, high)
        if start < chunk.stop:
            pieces.append(range(start, chunk.stop))
    return pieces


def covered_ids(config, covered):
    order = case_order(len(config.cases))
    return [order[p] for low, high in covered for p in range(low, high)]
