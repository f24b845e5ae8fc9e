"""The stages of `metrosync.simulate`, each consuming only what the one before gave:

``request``  the options, checked, and the memory and time they will take, before
             anything is allocated (`SimulationRequest`)
             -> the ensemble (`metrosync.ensemble`, built from the request)
``run``      the fixed-step driver or the whole-run integrator, giving records
``dataset``  the records as an `xarray.Dataset`

`metrosync.simulate` composes them; nothing here calls back up.
"""
