"""Running a render: the image cut into tiles and traced on worker processes (tiles.py, pool.py),
an animation's frames to files or a movie (frames.py, movie.py), many scenes in one run
(batch.py), a render again on every save (watch.py), and the files it writes (writer.py,
outputs.py).
"""
