"""Frame sequences: a time-dependent mesh drawn state by state, and the ghost2013 exploded view.

==============  ==================================================================
``frames``      the one frame loop (:func:`~.frames.draw_frames`), which every
                sequence of frames goes through, and :class:`~.frames.FrameLoop`:
                the states of a mesh drawn through one prepared path
``exploded``    the exploded-view animation of one part, frame by frame
``decoration``  the time stamp and colour bar drawn around each frame
``simplified``  the crash2000 decimation drawn over every state, each frame
                stamped with the bound certified at its state
==============  =================================================================="""
