//! The figure's page layout: every size and margin of the page (title, the line of what it
//! shows, the world panels, the legend and plots column), named once. Sizes are in font sizes
//! `f` ([`Pen::font`](super::world::Pen::font)) unless a field says otherwise.

/// The page layout's factors (see the [module docs](self)); the figure uses [`PAGE`].
pub(super) struct PageLayout {
    /// The pen grows with the figure: a line unit and the font per pixel of the shorter side
    /// (the reference side is [`PageLayout::reference_side`] pixels).
    pub reference_side: f64,
    /// The thinnest line unit, pixels.
    pub min_unit: f64,
    /// The font at the reference side, pixels.
    pub font_at_reference: f64,
    /// The smallest and largest font, pixels.
    pub font_range: [f64; 2],
    /// The title's start and baseline.
    pub title_at: [f64; 2],
    /// The title's size.
    pub title_size: f64,
    /// The baseline of the line saying what the figure shows.
    pub about_y: f64,
    /// Its size.
    pub about_size: f64,
    /// Where the body (worlds, column) starts.
    pub top: f64,
    /// The right column's share of the width (legend and plots)…
    pub column_share: f64,
    /// …and its least width.
    pub column_min: f64,
    /// A world's room inside its cell for the value axis' ticks and title, left…
    pub world_left: f64,
    /// …in all across (left and right)…
    pub world_across: f64,
    /// …and below (the x axis' ticks and title).
    pub world_below: f64,
    /// The least width and height of a world or a cell's body, pixels.
    pub min_size: f64,
    /// A panel title's line height.
    pub panel_title_line: f64,
    /// How far above its line a panel title's baseline sits.
    pub panel_title_raise: f64,
    /// The column's left inset, …
    pub column_inset: f64,
    /// …the width it gives up in all (inset and right margin), …
    pub column_trim: f64,
    /// …and its bottom margin.
    pub column_bottom: f64,
    /// The legend's largest share of the column when plots follow it.
    pub legend_share: f64,
    /// The gap between the legend and the plots.
    pub legend_gap: f64,
    /// The least height of one plot (more plots than fit are left out).
    pub plot_height: f64,
}

/// The layout of every figure.
pub(super) const PAGE: PageLayout = PageLayout {
    reference_side: 800.0,
    min_unit: 0.6,
    font_at_reference: 15.0,
    font_range: [8.0, 40.0],
    title_at: [0.8, 1.9],
    title_size: 1.5,
    about_y: 3.0,
    about_size: 0.9,
    top: 3.6,
    column_share: 0.34,
    column_min: 14.0,
    world_left: 5.0,
    world_across: 6.0,
    world_below: 4.0,
    min_size: 10.0,
    panel_title_line: 1.2,
    panel_title_raise: 0.4,
    column_inset: 0.5,
    column_trim: 1.3,
    column_bottom: 0.8,
    legend_share: 0.5,
    legend_gap: 1.0,
    plot_height: 10.5,
};
