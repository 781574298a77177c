"""The report's pages as drawn: text and images laid out in inches from the top left of an
A4 page, through matplotlib's PDF backend."""
import os

A4 = (8.27, 11.69)  # inches, portrait
MARGIN = 0.6


class Pdf:
    """Pages of text and images laid out in inches from the top left corner."""

    def __init__(self, path):
        import matplotlib
        matplotlib.use("pdf")
        matplotlib.rcParams["pdf.fonttype"] = 42  # TrueType: text can be searched and copied
        matplotlib.rcParams["font.family"] = "DejaVu Sans"
        from matplotlib.backends.backend_pdf import PdfPages
        from matplotlib.font_manager import FontProperties
        from matplotlib.textpath import TextToPath
        from matplotlib.transforms import Bbox, TransformedBbox
        self.Bbox, self.TransformedBbox = Bbox, TransformedBbox
        import matplotlib.pyplot as plt
        self.plt = plt
        self.pages = PdfPages(path)
        self.measure = TextToPath()
        self.FontProperties = FontProperties
        self.figure = None
        self.count = 0
        self.widths = {}

    def new_page(self):
        self.end_page()
        self.figure = self.plt.figure(figsize=A4)
        self.count += 1
        self.text(A4[0] - MARGIN, A4[1] - 0.35, f"page {self.count}", size=7, color="#888", ha="right")

    def end_page(self):
        if self.figure is not None:
            self.pages.savefig(self.figure)
            self.plt.close(self.figure)
            self.figure = None

    def close(self):
        self.end_page()
        self.pages.close()

    def font(self, style="normal", size=10):
        family = "DejaVu Sans Mono" if style == "code" else "DejaVu Sans"
        return self.FontProperties(family=family, size=size,
                                   weight="bold" if style == "bold" else "normal",
                                   style="italic" if style == "italic" else "normal")

    def width(self, text, style="normal", size=10):
        if not text:
            return 0.0
        key = (text, style, size)
        if key not in self.widths:  # a page measures the same words many times
            w, _, _ = self.measure.get_text_width_height_descent(text, self.font(style, size), ismath=False)
            self.widths[key] = w / 72.0
        return self.widths[key]

    @staticmethod
    def line_height(size, line=1.35):
        """Inches from one line's top to the next's. DejaVu's glyph box (ascent + descent)
        is 1.17 em: line spacing below about 1.2 lays lines over each other."""
        return size * line / 72.0

    def lines(self, text, width, size=9, style="normal"):
        """text (newlines kept) broken into lines no wider than width inches, measured:
        at spaces, and inside a word only where the word alone is wider than the line."""
        out = []
        for paragraph in text.split("\n"):
            current = ""
            for word in paragraph.split():
                candidate = current + " " + word if current else word
                if self.width(candidate, style, size) <= width:
                    current = candidate
                    continue
                if current:
                    out.append(current)
                while self.width(word, style, size) > width and len(word) > 1:
                    low, high = 1, len(word) - 1  # the longest head that fits: a binary search
                    while low < high:
                        mid = (low + high + 1) // 2
                        low, high = (mid, high) if self.width(word[:mid], style, size) <= width else (low, mid - 1)
                    cut = low
                    out.append(word[:cut])
                    word = word[cut:]
                current = word
            out.append(current)
        return out

    def fitted(self, text, width, size, style="normal", max_lines=2, smallest=5.5):
        """(lines, size): text in at most max_lines lines of width inches, without breaking a
        word, at the largest size from size down to smallest (then broken wherever it must)."""
        s = size
        while True:
            lines = self.lines(text, width, s, style)
            whole = all(self.width(w, style, s) <= width for w in text.split())
            if (len(lines) <= max_lines and whole) or s <= smallest:
                return lines, s
            s = max(smallest, s - 0.5)

    def text(self, x, y_top, text, size=10, style="normal", color="#222", ha="left", va="top", **kw):
        """Text at x inches from the left, y_top inches from the top."""
        self.figure.text(x / A4[0], 1.0 - y_top / A4[1], text, fontproperties=self.font(style, size), color=color,
                         ha=ha, va=va, parse_math=False, **kw)

    def image(self, path, x, y_top, w, h, title=None, border="#999"):
        """An image fitted into the box, centred, with a thin border. Drawn as a BboxImage and a
        rectangle, not an Axes: an Axes (ticks, spines) costs about ten times as much, and a
        report of every lab has 160 images."""
        import matplotlib.image as mpimg
        from matplotlib.patches import Rectangle
        pixels = mpimg.imread(path) if path and os.path.exists(path) else None
        if pixels is not None:
            # Lab 6's maps (2:1, square, 256x252) keep their shape inside the 4:3 box.
            scale = min(w / pixels.shape[1], h / pixels.shape[0])
            dw, dh = pixels.shape[1] * scale, pixels.shape[0] * scale
            bx, by = x + (w - dw) / 2, y_top + (h - dh) / 2
        else:
            bx, by, dw, dh = x, y_top, w, h
        bounds = (bx / A4[0], (A4[1] - by - dh) / A4[1], dw / A4[0], dh / A4[1])
        if pixels is not None:
            image = mpimg.BboxImage(self.TransformedBbox(self.Bbox.from_bounds(*bounds), self.figure.transFigure),
                                    interpolation="nearest", origin="upper")
            image.set_data(pixels)
            self.figure.add_artist(image)
        else:
            self.text(x + w / 2, y_top + h / 2, "no image", size=7, color="#777", ha="center", va="center")
        self.figure.patches.append(Rectangle(bounds[:2], bounds[2], bounds[3], transform=self.figure.transFigure,
                                             facecolor="none" if pixels is not None else "#eee", edgecolor=border,
                                             linewidth=0.8, zorder=2 if pixels is not None else 0))
        if title:
            lines, size = self.fitted(title, w, 7, max_lines=1)
            self.text(x, y_top + h + 0.01, " ".join(lines), size=size, color="#555")

    def box(self, x, y_top, w, h, color):
        from matplotlib.patches import Rectangle
        self.figure.patches.append(Rectangle((x / A4[0], (A4[1] - y_top - h) / A4[1]), w / A4[0], h / A4[1],
                                             transform=self.figure.transFigure, facecolor=color, edgecolor="none"))

    def wrapped(self, x, y, width, text, size=9, style="normal", color="#222", line=1.35, max_lines=None):
        """Plain text wrapped to width inches (measured); returns the y below it. Beyond
        max_lines the last line says how many more there were."""
        lines = self.lines(text, width, size, style)
        if max_lines and len(lines) > max_lines:
            lines = lines[:max_lines - 1] + [f"[... {len(lines) - max_lines + 1} more lines]"]
        for l in lines:
            self.text(x, y, l, size=size, style=style, color=color)
            y += self.line_height(size, line)
        return y
