//! What the page's address asks for:
//! `?scene=...&technique=...&set=KEY=VALUE&size=WxH&capture=N&judge=live`.

use zoo_host::glam::UVec2;

/// The address's choices; absent or unreadable ones are `None` (and logged).
#[derive(Debug, Default)]
pub struct Query {
    /// A bundled scene's file name (`planar-room.ron`).
    pub scene: Option<String>,
    /// The technique to show first.
    pub technique: Option<String>,
    /// Its parameters to set (`set=map_size=1024`, one `set` each), as the command line's
    /// `--set` takes them.
    pub set: Vec<(String, String)>,
    /// A fixed render size.
    pub size: Option<UVec2>,
    /// The frame (counted from 1) to keep for [`crate::frame`].
    pub capture: Option<u64>,
    /// Whether the live GPU judge starts on (`judge=live`).
    pub judge_live: bool,
}

impl Query {
    /// Reads the page's address.
    pub fn from_location() -> Query {
        let search = web_sys::window()
            .and_then(|w| w.location().search().ok())
            .unwrap_or_default();
        Query::parse(&search)
    }

    /// Reads a query string (`?a=b&c=d`).
    pub fn parse(search: &str) -> Query {
        let Ok(params) = web_sys::UrlSearchParams::new_with_str(search) else {
            return Query::default();
        };
        let size = params.get("size").and_then(|s| {
            let parsed = s.split_once('x').and_then(|(w, h)| {
                let size = UVec2::new(w.parse().ok()?, h.parse().ok()?);
                (size.min_element() >= 16 && size.max_element() <= 4096).then_some(size)
            });
            if parsed.is_none() {
                log::warn!("size={s}: expected WxH between 16 and 4096, e.g. size=256x256");
            }
            parsed
        });
        let capture = params.get("capture").and_then(|s| {
            let parsed = s.parse().ok().filter(|&n: &u64| n >= 1);
            if parsed.is_none() {
                log::warn!("capture={s}: expected a frame number from 1");
            }
            parsed
        });
        let judge_live = params.get("judge").is_some_and(|judge| {
            if judge != "live" {
                log::warn!("judge={judge}: the browser judges live on the GPU only (judge=live)");
            }
            judge == "live"
        });
        let set = (params.get_all("set").iter())
            .filter_map(|value| {
                let text = value.as_string()?;
                let pair = text
                    .split_once('=')
                    .map(|(k, v)| (k.to_string(), v.to_string()));
                if pair.is_none() {
                    log::warn!("set={text}: expected set=KEY=VALUE");
                }
                pair
            })
            .collect();
        Query {
            scene: params.get("scene"),
            technique: params.get("technique"),
            set,
            size,
            capture,
            judge_live,
        }
    }
}
