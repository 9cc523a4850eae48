"""Renders spread over a Dask cluster (README.md, "Clusters"); needs the extra `cluster`.

A still goes out as groups of tiles, about RAYS_PER_TASK primary rays each and at
least TASKS_PER_WORKER per worker, so that Dask's few milliseconds a task stay small
and every worker has work until the end; an animation goes out a frame a task. Every
pixel depends only on the scene and the pixel (jitter is hashed from the pixel's
coordinates, rtcli/rendering/tiles.py), so the images are byte for byte the ones a local render
makes, whatever the cluster's size, the grouping, or a worker that dies and whose
tasks run again elsewhere.

The scene reaches the workers as the bytes of the files the client read (the YAML,
its includes, meshes and textures), each file a task keyed by the SHA-256 of its
content: sent to the scheduler once, computed on one worker and copied between
workers as needed, and computed again if every copy is lost with its worker. A worker
builds the scene from those bytes (rtcli.scenefile.files.serving) and keeps the
built scenes of its last tasks, so the tiles of a still or the frames of an
animation reuse the parsed scene, its meshes and the engine.

Workers must run the same rtcli and libraries as the client, or pixels could differ:
the client compares every worker's `fingerprint()` with its own when it connects,
and every task compares it again where it runs (for workers that join later).

A worker that compiles the engine says so to the client while it does, and the client
says after the render which workers compiled and for how long (notes.py).

The folder: target.py (where the cluster is), software.py (the same software everywhere),
bundle.py (the scene as its files), session.py (a connection for one command, the client's
side), tasks.py (the workers' side), renders.py (a still or an animation on a cluster),
notes.py (what the workers' engines say) and warm.py (`rtcli warmup --cluster`).
distributed is imported only by this folder, and the folder only when a cluster option is
given.
"""
