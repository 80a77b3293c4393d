"""The command-line wing (the only argparse of the package), thin on top of the library.

``fibril-run`` (:mod:`.run`), ``fibril-campaign`` (:mod:`.campaign`), ``fibril-accuracy``
(:mod:`fibril_hpc.accuracy`); shared parser and exit statuses in :mod:`.common`; the console
scripts start in :mod:`.entry`, which answers Ctrl-C before anything heavy is imported (so this
package imports nothing itself). A user mistake is one line on stderr, exit status 2, nothing
written.
"""
