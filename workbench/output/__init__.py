"""What the workbench writes: tables, figures, videos and meshes, atomically and only where allowed.

============  ================================================================
``targets``   where output may go (a regular file replaced whole, or a folder)
``swap``      a folder of outputs replaced whole (staging folder, then renames)
``tables``    CSV and aligned Markdown tables, atomic writes
``figures``   PNGs, field images with a colour bar, comparison grids, animations
``video``     frames as MP4 or GIF
``export``    a triangle surface written to a mesh file
============  ================================================================"""
