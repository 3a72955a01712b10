"""The output layer: what a solve writes. The contact output of a pair (:mod:`.contact_output`),
atomic files and checkpoints (:mod:`.io`), one run per output directory (:mod:`.outdir`) and
pictures (:mod:`.plot`).
"""
