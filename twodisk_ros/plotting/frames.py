"""Frames of an animation drawn fast: the still parts of a figure drawn once, then per frame
only what moves, in matplotlib's own drawing order (:func:`render`); GIF frames as matplotlib's
PillowWriter makes them (:func:`gif_frame`), in one palette for the whole GIF
(:func:`one_palette`). Used by :mod:`twodisk_ros.plotting.animation`.
"""

__all__ = ['render', 'gif_frame', 'one_palette']


def _moving(scene):
    """The artists of the axes that change from frame to frame."""
    lines = [scene.trace_a, scene.trace_b, scene.path_g, scene.segment, scene.centre]
    shapes = [scene.polys] if scene.view == '3d' else list(scene.patches)
    return shapes + lines + list(scene.arrows)


def _axes_order(ax):
    """The axes' children in the order ``Axes.draw`` draws them (after the background patch,
    the 3D panes and axes): by zorder, ties in the order of the children; in 3D the
    collections' zorders are first computed from their depths as ``Axes3D.draw`` does."""
    three_d = getattr(ax, 'name', '') == '3d'
    axes = (ax.xaxis, ax.yaxis, ax.zaxis) if three_d else (ax.xaxis, ax.yaxis)
    if three_d:
        from matplotlib.collections import Collection
        from matplotlib.patches import Patch
        children = set(ax.collections) | set(ax.patches)   # Axes3D's own children
        shapes = [a for a in ax.get_children() if a in children and a.get_visible()]
        if ax.computed_zorder:
            offset = max(axis.get_zorder() for axis in axes) + 1
            zorder = {Collection: offset, Patch: offset}
            for artist in sorted(shapes, key=lambda a: a.do_3d_projection(), reverse=True):
                kind = Collection if isinstance(artist, Collection) else Patch
                artist.zorder = zorder[kind]
                zorder[kind] += 1
        else:
            for artist in shapes:
                artist.do_3d_projection()
    children = ax.get_children()
    children.remove(ax.patch)
    if not (ax.axison and ax.get_frame_on()):
        children = [a for a in children if a not in ax.spines.values()]
    if not ax.axison:
        children = [a for a in children if a not in axes]
    return sorted(children, key=lambda a: a.zorder)


def render(scene):
    """Draw the scene's current frame on its Agg canvas; return the RGBA buffer.

    The legend and the title are the same in every frame, and with the 'fit' camera so are
    the axes, their ticks and labels: these still parts are drawn once (the background)
    and each frame then draws, over a copy of it, only what moves (the clock, and the
    moving artists, or with a following camera the whole axes) and the still artists that
    ``Figure.draw`` would draw over them, in ``Figure.draw``'s order: the same picture as a
    full redraw (tests/test_animation.py compares them pixel by pixel) in a fraction of the
    time (the text of the ticks and the legend is most of a full redraw).
    """
    canvas, ax, figure = scene.figure.canvas, scene.ax, scene.figure
    fit = scene.camera == 'fit'
    moving = _moving(scene) if fit else [ax]
    for artist in moving + [scene.clock]:
        artist.set_animated(True)
    if scene.background is None:
        canvas.draw()                               # lays out the figure (and sets ax.M)
        if fit:
            order = _axes_order(ax)
            first = min(order.index(a) for a in moving)
            # still artists drawn after a moving one are drawn again over it in each frame
            scene.overlays = [a for a in order[first:] if a not in moving]
            for artist in scene.overlays:
                artist.set_animated(True)
        renderer = canvas.get_renderer()
        # everything drawn in the axes is clipped to them: a still figure artist drawn after
        # the axes is drawn again in each frame only where it overlaps them
        for artist in figure.get_children()[1:]:
            if artist is ax or artist.get_animated():
                continue
            if artist.zorder >= ax.zorder and artist.get_window_extent(renderer).overlaps(
                    ax.bbox):
                artist.set_animated(True)
        canvas.draw()
        scene.background = canvas.copy_from_bbox(figure.bbox)
    renderer = canvas.get_renderer()
    canvas.restore_region(scene.background)
    if fit:
        for artist in _axes_order(ax):
            if artist.get_animated():
                artist.draw(renderer)
    for artist in sorted(figure.get_children()[1:], key=lambda a: a.zorder):
        if artist.get_animated():
            artist.draw(renderer)
    return canvas.buffer_rgba()


def gif_frame(buffer, size):
    """One GIF frame from an RGBA buffer, as matplotlib's PillowWriter makes it."""
    from PIL import Image
    image = Image.frombuffer('RGBA', size, bytes(buffer), 'raw', 'RGBA', 0, 1)
    return image if image.getextrema()[3][0] < 255 else image.convert('RGB')


def one_palette(images):
    """The frames of a GIF (RGB images of one size) in one palette of 256 colours.

    The palette is chosen once, by Pillow's max-coverage quantizer over the first, middle
    and last frames side by side (the still parts, both laminae, the traces grown), and
    each frame takes its nearest colours, not dithered. Pillow's own way (what matplotlib's
    PillowWriter gets) makes a median-cut palette for every frame: ~30 ms a 640 × 480
    frame, a third of the time a frame of ``twodisk-animate`` took, against ~3 ms here,
    and the GIF comes out about a third smaller. The pictures differ from the drawn frames
    by the rounding of colours only: a few levels of 255 on average, as light flat colours
    (the ground's pane) round to a neighbour in the palette (tests/test_animation.py bounds
    it). Frames with
    transparency (not RGB) are returned as they are, for Pillow's own way.
    """
    from PIL import Image
    if not images or any(image.mode != 'RGB' for image in images):
        return images
    width, height = images[0].size
    picks = sorted({0, len(images) // 2, len(images) - 1})
    montage = Image.new('RGB', (width, height * len(picks)))
    for row, k in enumerate(picks):
        montage.paste(images[k], (0, height * row))
    palette = montage.quantize(256, method=Image.Quantize.MAXCOVERAGE)
    return [image.quantize(palette=palette, dither=Image.Dither.NONE) for image in images]
