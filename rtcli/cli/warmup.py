"""`rtcli warmup` (README.md, "The first compiled render"): the compiled engine compiled now, or
loaded from numba's cache, its machine code files written; on every worker of a cluster with a
cluster option (rtcli/cluster/warm.py)."""

from __future__ import annotations

import time

import click

from rtcli.cli.options import cluster_options, reach
from rtcli.cli.terminal import note


@click.command()
@cluster_options("Warm every worker of", " This machine is not warmed.")
def warmup(cluster, cluster_file, local_cluster, cluster_timeout):
    """Compile the render engine now (about half a minute, once), or load it from numba's cache; say
    where the cache is and how long it took. Renders then start at once. With a cluster option:
    on every worker of the cluster at once, a line for each."""
    where = reach(cluster, cluster_file, local_cluster, note, cluster_timeout)
    if where is not None:
        from rtcli.cluster.warm import warm  # start-up: Dask only when asked
        with where:
            return warm(where.session(), click.echo)
    from rtcli.kernels import numba_cache, variants  # start-up
    from rtcli.kernels import machinecode
    from rtcli.rendering.warmup import bytecode
    from rtcli.rendering.warmup import warmup as warm
    start = time.perf_counter()
    machinecode.report_to(lambda text: click.echo(f"note: {text}", err=True))
    where = numba_cache.cache_location() if variants.ENABLED else None
    if where is not None:
        click.echo(f"cache: {where} ({where.why})" if where.enabled else f"cache: none ({where.why}); "
                   f"set {numba_cache.CACHE_ENV} to a writable folder")
    done, (files, why) = warm(notes=lambda text: click.echo(f"note: {text}", err=True))
    for what, load in done:
        how = f"compiled in {load.compile_seconds:.1f} s" if load.compile_seconds else "loaded from the cache"
        click.echo(f"{what}: {how}, ready in {load.seconds:.2f} s")
    click.echo(f"machine code files: {', '.join(files) or 'none'} in {machinecode.folder()}" +
               (" (renders start without numba)" if files else "") + (f"; not written: {why}" if why else ""))
    if not bytecode():
        click.echo("note: rtcli's folder is read-only: its Python files were not compiled to bytecode", err=True)
    compiled = sum(load.compile_seconds for _, load in done)
    click.echo(f"{'compiled' if compiled else 'warm: nothing to compile'}; {time.perf_counter() - start:.2f} s in all")
